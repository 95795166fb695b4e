"""Reads a ROS 1 bag's pose-with-covariance messages with the Python `rosbags` package: the
twin of benches/bag_read.rs (posecov's streamed reader). Every chunk is decompressed and every
nav_msgs/Odometry, PoseWithCovarianceStamped and PoseWithCovariance message deserialized; the
covariance is touched (posecov also classifies its health, which this side does not).

Usage: python bag_rosbags.py BAG [--repeats 5]; prints messages per second (best of repeats).
       python bag_rosbags.py BAG --rewrite OUT --compression none|lz4|bz2 [--copies K] [--ekf]
         writes the bag again (K times over, stamps shifted) with that chunk compression, so
         both readers can be compared on the same messages in every compression. With --ekf,
         every Odometry's pose covariance is replaced by a new one in each message, as an EKF
         publishes (see ekf_covariance): the bags as shipped publish one covariance throughout.
"""

import argparse
import time
from pathlib import Path

import numpy as np
from rosbags.rosbag1 import Reader, Writer
from rosbags.typesys import Stores, get_typestore

TYPES = {
    "nav_msgs/msg/Odometry",
    "geometry_msgs/msg/PoseWithCovarianceStamped",
    "geometry_msgs/msg/PoseWithCovariance",
}


def read(path: Path, typestore) -> tuple[int, float]:
    n, total = 0, 0.0
    with Reader(path) as reader:
        conns = [c for c in reader.connections if c.msgtype in TYPES]
        for conn, _t, raw in reader.messages(connections=conns):
            msg = typestore.deserialize_ros1(raw, conn.msgtype)
            pose = msg.pose if conn.msgtype != "geometry_msgs/msg/PoseWithCovariance" else msg
            total += float(pose.covariance[0])
            n += 1
    return n, total


def ekf_covariance(k: int, n: int) -> np.ndarray:
    """Message k of n's pose covariance, as a 3-D EKF publishes it: all six axes estimated,
    correlated (x with y and yaw, y with yaw, z with roll and pitch), symmetric positive
    definite, growing slowly (×4 over the log, linearly: never a drop, never × 100) and so
    different in every message."""
    sigma = np.array([0.03, 0.03, 0.05, 0.01, 0.01, 0.17])
    corr = np.eye(6)
    for i, j, rho in [(0, 1, 0.3), (0, 5, 0.2), (1, 5, 0.4), (2, 3, 0.1), (2, 4, -0.1)]:
        corr[i, j] = corr[j, i] = rho
    cov = np.outer(sigma, sigma) * corr * (1.0 + 3.0 * k / max(n - 1, 1))
    return cov.reshape(36)


def rewrite(src: Path, out: Path, compression: str, copies: int, ekf: bool = False) -> None:
    out.unlink(missing_ok=True)
    writer = Writer(out)
    if compression != "none":
        writer.set_compression(getattr(Writer.CompressionFormat, compression.upper()))
    with Reader(src) as reader, writer:
        conns = {}
        for c in reader.connections:
            conns[c.id] = writer.add_connection(
                c.topic, c.msgtype, msgdef=c.msgdef.data, md5sum=c.digest
            )
        span = reader.end_time - reader.start_time + 1
        typestore = get_typestore(Stores.ROS1_NOETIC)
        odometry = "nav_msgs/msg/Odometry"
        n = copies * sum(c.msgcount for c in reader.connections if c.msgtype == odometry)
        j = 0
        for k in range(copies):
            for conn, t, raw in reader.messages():
                if ekf and conn.msgtype == odometry:
                    msg = typestore.deserialize_ros1(raw, odometry)
                    msg.pose.covariance = ekf_covariance(j, n)
                    raw = typestore.serialize_ros1(msg, odometry)
                    j += 1
                writer.write(conns[conn.id], t + k * span, raw)


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("bag", type=Path)
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--rewrite", type=Path)
    ap.add_argument("--compression", choices=["none", "lz4", "bz2"], default="none")
    ap.add_argument("--copies", type=int, default=1)
    ap.add_argument("--ekf", action="store_true", help="a new pose covariance in every message")
    args = ap.parse_args()
    if args.rewrite:
        rewrite(args.bag, args.rewrite, args.compression, args.copies, args.ekf)
        return
    typestore = get_typestore(Stores.ROS1_NOETIC)
    best = float("inf")
    n = 0
    for _ in range(args.repeats):
        start = time.perf_counter()
        n, _ = read(args.bag, typestore)
        best = min(best, time.perf_counter() - start)
    print(f"rosbags: {n} pose messages in {best * 1e3:.2f} ms (best of {args.repeats}): "
          f"{n / best:,.0f} messages/s")


if __name__ == "__main__":
    main()
