"""Reads a ROS 2 bag (rosbag2 directory, SQLite storage) with the Python `rosbags` package: the
twin of benches/bag_read.rs's `bag_read/db3_*` (posecov's streamed reader). Every
nav_msgs/msg/Odometry, PoseWithCovarianceStamped and PoseWithCovariance message is read and
deserialized from CDR (zstd-compressed messages or files decompressed by rosbags); the
covariance is touched (posecov also classifies its health, which this side does not).

Usage: python db3_rosbags.py BAG_DIR [--repeats 5]; prints pose messages per second (best of
         repeats).
       python db3_rosbags.py BAG_DIR --rewrite OUT --compression none|message|file [--copies K]
         writes the bag again with rosbags' writer (version 9, SQLite), K times over with
         stamps shifted, with that zstd compression mode, so both readers read the same
         messages.
"""

import argparse
import time
from pathlib import Path

from rosbags.rosbag2 import Reader, Writer
from rosbags.rosbag2.enums import CompressionFormat, CompressionMode
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
            msg = typestore.deserialize_cdr(raw, conn.msgtype)
            pose = msg.pose if conn.msgtype != "geometry_msgs/msg/PoseWithCovariance" else msg
            total += float(pose.covariance[0])
            n += 1
    return n, total


def rewrite(src: Path, out: Path, compression: str, copies: int) -> None:
    typestore = get_typestore(Stores.ROS2_HUMBLE)
    writer = Writer(out, version=9)
    if compression != "none":
        writer.set_compression(getattr(CompressionMode, compression.upper()), CompressionFormat.ZSTD)
    with Reader(src) as reader, writer:
        conns = {c.id: writer.add_connection(c.topic, c.msgtype, typestore=typestore) for c in reader.connections}
        span = reader.end_time - reader.start_time + 1
        for k in range(copies):
            for conn, t, raw in reader.messages():
                writer.write(conns[conn.id], t + k * span, raw)


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("bag", type=Path)
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--rewrite", type=Path)
    ap.add_argument("--compression", choices=["none", "message", "file"], default="none")
    ap.add_argument("--copies", type=int, default=1)
    args = ap.parse_args()
    if args.rewrite:
        rewrite(args.bag, args.rewrite, args.compression, args.copies)
        return
    typestore = get_typestore(Stores.ROS2_HUMBLE)
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
