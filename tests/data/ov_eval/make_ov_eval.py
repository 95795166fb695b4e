#!/usr/bin/env python3
"""Writes the ov_eval test trajectories of this directory (standard library only, seeded).

    python3 tests/data/ov_eval/make_ov_eval.py tests/data/ov_eval

- gt.txt: a TUM ground truth (timestamp tx ty tz qx qy qz qw), 20 Hz for 20 s, a helix
  with roll up to 0.6 rad and pitch up to 0.4 rad.
- estimate.txt: an ov_eval trajectory at 10 Hz (200 lines of 20 columns, ov_eval's header),
  each pose the truth moved by an error drawn from the covariance it states, in ov_eval's
  meaning (OpenVINS ov_eval ResultTrajectory::calculate_nees): the position error
  p_gt - p_est ~ N(0, Pt) in the global frame, the rotation error theta with
  R_gt = R_est Exp(theta) ~ N(0, Pr) in the body frame, no cross-covariance. Pt and Pr are
  anisotropic with off-diagonal terms and change along the run.
- overconfident.txt: the same poses stating a tenth of each covariance.
"""
import math
import random
import sys

def quat_mul(a, b):
    ax, ay, az, aw = a
    bx, by, bz, bw = b
    return (aw * bx + ax * bw + ay * bz - az * by,
            aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw,
            aw * bw - ax * bx - ay * by - az * bz)

def quat_rpy(roll, pitch, yaw):
    # R = Rz(yaw) Ry(pitch) Rx(roll), Hamilton, (x, y, z, w)
    qx = (math.sin(roll / 2), 0.0, 0.0, math.cos(roll / 2))
    qy = (0.0, math.sin(pitch / 2), 0.0, math.cos(pitch / 2))
    qz = (0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2))
    return quat_mul(qz, quat_mul(qy, qx))

def quat_exp(t):
    n = math.sqrt(sum(v * v for v in t))
    if n < 1e-12:
        return (t[0] / 2, t[1] / 2, t[2] / 2, 1.0)
    s = math.sin(n / 2) / n
    return (t[0] * s, t[1] * s, t[2] * s, math.cos(n / 2))

def cholesky(m):
    l = [[0.0] * 3 for _ in range(3)]
    for i in range(3):
        for j in range(i + 1):
            s = m[i][j] - sum(l[i][k] * l[j][k] for k in range(j))
            l[i][j] = math.sqrt(s) if i == j else s / l[j][j]
    return l

def draw(rng, m):
    l = cholesky(m)
    z = [rng.gauss(0.0, 1.0) for _ in range(3)]
    return [sum(l[i][k] * z[k] for k in range(3)) for i in range(3)]

def truth(t):
    p = (5 * math.cos(0.2 * t), 5 * math.sin(0.2 * t), 0.5 * t)
    q = quat_rpy(0.6 * math.sin(0.5 * t), 0.4 * math.cos(0.3 * t), 0.2 * t + 0.3)
    return p, q

def upper(m):
    return [m[0][0], m[0][1], m[0][2], m[1][1], m[1][2], m[2][2]]

def main(out):
    rng = random.Random(32)
    t0 = 1403636580.0
    with open(f"{out}/gt.txt", "w") as f:
        f.write("# timestamp(s) tx ty tz qx qy qz qw\n")
        for k in range(401):
            t = k * 0.05
            p, q = truth(t)
            f.write("%.6f %.9f %.9f %.9f %.12f %.12f %.12f %.12f\n" % ((t0 + t,) + p + q))
    header = ("# timestamp(s) tx ty tz qx qy qz qw Pr11 Pr12 Pr13 Pr22 Pr23 Pr33 "
              "Pt11 Pt12 Pt13 Pt22 Pt23 Pt33\n")
    est = open(f"{out}/estimate.txt", "w")
    over = open(f"{out}/overconfident.txt", "w")
    for f in (est, over):
        f.write(header)
    for k in range(1, 201):
        t = k * 0.1
        p, q = truth(t)
        g = 1.0 + 0.02 * k  # the covariance grows along the run
        pr = [[4e-4 * g, 1e-4 * g, 0.0], [1e-4 * g, 1e-4 * g, -3e-5 * g], [0.0, -3e-5 * g, 9e-4 * g]]
        pt = [[0.04 * g, 0.01 * g, 0.005 * g], [0.01 * g, 0.01 * g, 0.0], [0.005 * g, 0.0, 0.0225 * g]]
        theta = draw(rng, pr)
        dp = draw(rng, pt)
        # R_gt = R_est Exp(theta): R_est = R_gt Exp(-theta); p_est = p_gt - dp.
        qe = quat_mul(q, quat_exp([-v for v in theta]))
        if qe[3] < 0:
            qe = tuple(-v for v in qe)
        pe = tuple(p[i] - dp[i] for i in range(3))
        pose = "%.6f %.9f %.9f %.9f %.12f %.12f %.12f %.12f" % ((t0 + t,) + pe + qe)
        for f, scale in ((est, 1.0), (over, 0.1)):
            cov = [v * scale for v in upper(pr) + upper(pt)]
            f.write(pose + " " + " ".join("%.10g" % v for v in cov) + "\n")
    est.close()
    over.close()

if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else ".")
