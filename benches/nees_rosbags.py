"""NEES of a log's estimates against its ground truth with the Python `rosbags` package and
NumPy: the twin of `posecov report LOG --reference /ground_truth` (examples/nees_bench.rs), the
same computation as posecov's eval/nees.rs (docs/CONVENTIONS.md §6 and §11):

- every message of the MCAP file read with rosbags' own MCAP storage reader (the plugin its
  rosbag2 Reader uses for a bag directory's .mcap files) and deserialized with
  `typestore.deserialize_cdr`: the reference topic's PoseStamped samples, and every
  nav_msgs/Odometry or PoseWithCovarianceStamped topic's pose and covariance;
- the truth interpolated on SE(3) at each estimate's header stamp between the two reference
  samples that bracket it, X_a · Exp(s · Log(X_a⁻¹ X_b)); a stamp outside the reference is
  skipped, never extrapolated;
- the covariance read in tf2's reading (both blocks in the parent axes) and moved to the right
  form, Σ_right = blkdiag(Rᵀ, Rᵀ) Σ_ros blkdiag(R, R);
- e = Log(X̂⁻¹ · X_ref) = [ρ; θ] on SE(3), the joint NEES eᵀ Σ⁻¹ e (d = 6), the position NEES
  of R̂ᵀ(p_ref − p̂) against Σ_ρρ and the orientation NEES of θ = Log(R̂ᵀ R_ref) against
  Σ_θθ (ov_eval's), per topic their means (ANEES) and the share of joint NEES ≤ χ²_6(0.95).

Vectorised over all messages once they are read. 3-D topics only (posecov also handles planar
ones; the benchmark log has none).

Usage: python nees_rosbags.py LOG.mcap [--reference /ground_truth]; prints one JSON line per
estimate topic (the keys of examples/nees_bench.rs) with the seconds taken.
"""

import argparse
import json
import time
from pathlib import Path

import numpy as np
from rosbags.rosbag2.storage_mcap import McapReader
from rosbags.typesys import Stores, get_typestore

ESTIMATE_TYPES = {"nav_msgs/msg/Odometry", "geometry_msgs/msg/PoseWithCovarianceStamped"}
REFERENCE_TYPES = {"geometry_msgs/msg/PoseStamped"}
# χ²_6(0.95), the per-message bound of inside_95.
BOUND_95_DOF6 = 12.591587243743977


def stamp_ns(header) -> int:
    return header.stamp.sec * 1_000_000_000 + header.stamp.nanosec


def read(path: Path, reference: str):
    """The reference's (stamps, positions, quaternions xyzw) and per estimate topic its
    (stamps, positions, quaternions, 6×6 covariances)."""
    typestore = get_typestore(Stores.ROS2_HUMBLE)
    truth = ([], [], [])
    topics: dict[str, tuple[list, list, list, list]] = {}
    reader = McapReader(path)
    reader.open()
    try:
        conns = [
            c
            for c in reader.connections
            if (c.topic == reference and c.msgtype in REFERENCE_TYPES)
            or (c.topic != reference and c.msgtype in ESTIMATE_TYPES)
        ]
        for conn, _t, raw in reader.messages(connections=conns):
            msg = typestore.deserialize_cdr(raw, conn.msgtype)
            if conn.topic == reference:
                p, q = msg.pose.position, msg.pose.orientation
                truth[0].append(stamp_ns(msg.header))
                truth[1].append((p.x, p.y, p.z))
                truth[2].append((q.x, q.y, q.z, q.w))
            else:
                lists = topics.setdefault(conn.topic, ([], [], [], []))
                pose = msg.pose.pose
                p, q = pose.position, pose.orientation
                lists[0].append(stamp_ns(msg.header))
                lists[1].append((p.x, p.y, p.z))
                lists[2].append((q.x, q.y, q.z, q.w))
                lists[3].append(msg.pose.covariance)
    finally:
        reader.close()
    truth = tuple(np.asarray(a) for a in truth)
    topics = {
        name: (
            np.asarray(s, dtype=np.int64),
            np.asarray(p),
            np.asarray(q),
            np.asarray(c).reshape(-1, 6, 6),
        )
        for name, (s, p, q, c) in topics.items()
    }
    return truth, topics


# --- SO(3) and SE(3), batched; quaternions xyzw, tangents [ρ; θ] as posecov's ---


def qnormalize(q):
    return q / np.linalg.norm(q, axis=-1, keepdims=True)


def qmul(a, b):
    ax, ay, az, aw = np.moveaxis(a, -1, 0)
    bx, by, bz, bw = np.moveaxis(b, -1, 0)
    return np.stack(
        [
            aw * bx + ax * bw + ay * bz - az * by,
            aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw,
            aw * bw - ax * bx - ay * by - az * bz,
        ],
        axis=-1,
    )


def qconj(q):
    return q * np.array([-1.0, -1.0, -1.0, 1.0])


def qmatrix(q):
    x, y, z, w = np.moveaxis(q, -1, 0)
    return np.stack(
        [
            np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)], -1),
            np.stack([2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)], -1),
            np.stack([2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)], -1),
        ],
        axis=-2,
    )


def qlog(q):
    """The rotation vector θ of a unit quaternion (the short way round)."""
    q = np.where(q[..., 3:4] < 0, -q, q)
    v, w = q[..., :3], q[..., 3]
    n = np.linalg.norm(v, axis=-1)
    angle = 2.0 * np.arctan2(n, w)
    small = n < 1e-12
    scale = np.where(small, 2.0 / np.where(w == 0, 1.0, w), angle / np.where(small, 1.0, n))
    return v * scale[..., None]


def qexp(phi):
    angle = np.linalg.norm(phi, axis=-1)
    half = 0.5 * angle
    small = angle < 1e-8
    k = np.where(small, 0.5 - angle * angle / 48.0, np.sin(half) / np.where(small, 1.0, angle))
    return np.concatenate([phi * k[..., None], np.cos(half)[..., None]], axis=-1)


def skew(v):
    x, y, z = np.moveaxis(v, -1, 0)
    o = np.zeros_like(x)
    return np.stack(
        [np.stack([o, -z, y], -1), np.stack([z, o, -x], -1), np.stack([-y, x, o], -1)], -2
    )


def jl(phi):
    """SO(3)'s left Jacobian (SE(3)'s V): I + (1 − cos θ)/θ² Φ + (θ − sin θ)/θ³ Φ²."""
    t = np.linalg.norm(phi, axis=-1)
    small = t < 1e-4
    ts = np.where(small, 1.0, t)
    a = np.where(small, 0.5 - t * t / 24.0, (1 - np.cos(ts)) / ts**2)
    b = np.where(small, 1.0 / 6.0 - t * t / 120.0, (ts - np.sin(ts)) / ts**3)
    s = skew(phi)
    return np.eye(3) + a[..., None, None] * s + b[..., None, None] * (s @ s)


def jl_inv(phi):
    """I − Φ/2 + (1/θ² − (1 + cos θ)/(2θ sin θ)) Φ²."""
    t = np.linalg.norm(phi, axis=-1)
    small = t < 1e-4
    ts = np.where(small, 1.0, t)
    c = np.where(small, 1.0 / 12.0 + t * t / 720.0, 1 / ts**2 - (1 + np.cos(ts)) / (2 * ts * np.sin(ts)))
    s = skew(phi)
    return np.eye(3) - 0.5 * s + c[..., None, None] * (s @ s)


def se3_between(qa, pa, qb, pb):
    """X_a⁻¹ X_b as (q, t)."""
    ra = qmatrix(qa)
    return qmul(qconj(qa), qb), np.einsum("nji,nj->ni", ra, pb - pa)


def se3_log(q, t):
    theta = qlog(q)
    rho = np.einsum("nij,nj->ni", jl_inv(theta), t)
    return rho, theta


def interpolate(stamps, qs, ps, at):
    """The truth at `at` (inside the reference's span) on SE(3)."""
    i = np.searchsorted(stamps, at, side="left")
    exact = stamps[i] == at
    i0 = np.where(exact | (i == 0), i, i - 1)
    i1 = i
    span = (stamps[i1] - stamps[i0]).astype(float)
    s = np.where(span > 0, (at - stamps[i0]) / np.where(span > 0, span, 1.0), 0.0)
    qa, pa = qs[i0], ps[i0]
    qd, td = se3_between(qa, pa, qs[i1], ps[i1])
    rho, theta = se3_log(qd, td)
    rho, theta = rho * s[:, None], theta * s[:, None]
    q = qmul(qa, qexp(theta))
    p = pa + np.einsum("nij,nj->ni", qmatrix(qa), np.einsum("nij,nj->ni", jl(theta), rho))
    return np.where(exact[:, None], qs[i1], q), np.where(exact[:, None], ps[i1], p)


def nees(truth, estimates):
    t_stamps, t_pos, t_q = truth
    order = np.argsort(t_stamps, kind="stable")
    t_stamps, t_pos, t_q = t_stamps[order], t_pos[order], qnormalize(t_q[order])
    stamps, pos, q, cov = estimates
    inside = (stamps >= t_stamps[0]) & (stamps <= t_stamps[-1])
    stamps, pos, q, cov = stamps[inside], pos[inside], qnormalize(q[inside]), cov[inside]
    q_ref, p_ref = interpolate(t_stamps, t_q, t_pos, stamps)
    qe, te = se3_between(q, pos, q_ref, p_ref)
    rho, theta = se3_log(qe, te)
    e = np.concatenate([rho, theta], axis=-1)
    r = qmatrix(q)
    b = np.zeros((len(stamps), 6, 6))
    b[:, :3, :3] = np.swapaxes(r, 1, 2)
    b[:, 3:, 3:] = np.swapaxes(r, 1, 2)
    right = b @ cov @ np.swapaxes(b, 1, 2)
    joint = np.einsum("ni,ni->n", e, np.linalg.solve(right, e[..., None])[..., 0])
    position = np.einsum("ni,ni->n", te, np.linalg.solve(right[:, :3, :3], te[..., None])[..., 0])
    orientation = np.einsum(
        "ni,ni->n", theta, np.linalg.solve(right[:, 3:, 3:], theta[..., None])[..., 0]
    )
    return {
        "messages": int(len(stamps)),
        "anees": float(joint.mean()),
        "anees_position": float(position.mean()),
        "anees_orientation": float(orientation.mean()),
        "inside_95": float(np.mean(joint <= BOUND_95_DOF6)),
        "skipped_outside_reference": int((~inside).sum()),
    }


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("log", type=Path)
    ap.add_argument("--reference", default="/ground_truth")
    args = ap.parse_args()
    start = time.perf_counter()
    truth, topics = read(args.log, args.reference)
    results = {name: nees(truth, estimates) for name, estimates in sorted(topics.items())}
    seconds = time.perf_counter() - start
    for name, r in results.items():
        print(json.dumps({"side": "rosbags", "topic": name, **r, "seconds": seconds}))


if __name__ == "__main__":
    main()
