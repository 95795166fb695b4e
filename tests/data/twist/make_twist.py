"""Writes tests/data/twist/ with PyPI `rosbags` (0.11.9), an independent writer of ROS 1 bags
and rosbag2 SQLite bags: the same synthetic velocity, acceleration and odometry messages as a
ROS 1 bag (`twist.bag`) and as a ROS 2 bag directory (`twist_db3/`, version 9, CDR). Every
message is made here (seeded), so the files carry no one else's data.

Usage (from the repository root, in a virtualenv with `pip install rosbags==0.11.9 numpy`):
    python tests/data/twist/make_twist.py tests/data/twist

Topics (stamps 0.02 s apart from 1 700 000 000 s):
  /wheel/twist  geometry_msgs/TwistWithCovarianceStamped, 50 messages, frame base_link: an
                honest wheel-odometry velocity: σ vx = 0.02 + 0.05·|vx| m/s (grows with speed),
                σ vy = σ vz = 0.01 m/s, σ ωx = σ ωy = 0.005 rad/s, σ ωz = 0.01 + 0.02·|ωz| rad/s
  /vo/twist     geometry_msgs/TwistWithCovarianceStamped, 30 messages, frame camera: a visual
                odometry velocity with two defects: from message 10 on its linear block
                correlates vx and vy beyond 1 (not positive semi-definite), and its angular
                block is all zero in every message
  /imu/accel    geometry_msgs/AccelWithCovarianceStamped, 40 messages, frame imu_link: linear
                σ 0.05 m/s² (constant), angular acceleration "not provided" (-1 in element 0)
  /odom         nav_msgs/Odometry, 50 messages, odom -> base_link: a pose covariance growing with
                the distance, and a twist covariance in base_link (child_frame_id): σ vx
                0.03 m/s, σ vy = σ vz 0.01 m/s, variance of ωx and ωy 1e6 (placeholders: a planar robot),
                σ ωz 0.02 + 0.01·k/50 rad/s
"""

import math
import shutil
import sys
from pathlib import Path

import numpy as np
from rosbags.rosbag1 import Writer as Writer1
from rosbags.rosbag2 import Writer as Writer2
from rosbags.rosbag2.enums import StoragePlugin
from rosbags.typesys import Stores, get_typestore

START_NS = 1_700_000_000 * 10**9
STEP_NS = 20_000_000
TWIST = "geometry_msgs/msg/TwistWithCovarianceStamped"
ACCEL = "geometry_msgs/msg/AccelWithCovarianceStamped"
ODOM = "nav_msgs/msg/Odometry"


def messages(ts):
    """Every message in log-time order: (topic, type, log time ns, message)."""
    T = ts.types
    rng = np.random.default_rng(32)
    ros1 = "seq" in T["std_msgs/msg/Header"].__dataclass_fields__

    def header(seq, t_ns, frame):
        extra = {"seq": seq} if ros1 else {}
        stamp = T["builtin_interfaces/msg/Time"](sec=t_ns // 10**9, nanosec=t_ns % 10**9)
        return T["std_msgs/msg/Header"](stamp=stamp, frame_id=frame, **extra)

    def vec(x, y, z):
        return T["geometry_msgs/msg/Vector3"](x=float(x), y=float(y), z=float(z))

    def six(diagonal):
        return np.diag(np.array(diagonal, dtype=np.float64) ** 2)

    out = []
    for k in range(50):
        t = START_NS + k * STEP_NS
        vx = 0.5 + 0.5 * math.sin(0.1 * k) + 0.01 * rng.standard_normal()
        wz = 0.2 * math.cos(0.1 * k)
        cov = six([0.02 + 0.05 * abs(vx), 0.01, 0.01, 0.005, 0.005, 0.01 + 0.02 * abs(wz)])
        twist = T["geometry_msgs/msg/TwistWithCovariance"](
            twist=T["geometry_msgs/msg/Twist"](linear=vec(vx, 0, 0), angular=vec(0, 0, wz)),
            covariance=cov.reshape(36),
        )
        msg = T[TWIST](header=header(k, t, "base_link"), twist=twist)
        out.append(("/wheel/twist", TWIST, t + 1_000_000, msg))

        odom_twist_cov = six([0.03, 0.01, 0.01, 1e3, 1e3, 0.02 + 0.01 * k / 50])
        yaw = 0.02 * k
        pose_cov = six([0.01 + 0.002 * k, 0.01 + 0.002 * k, 1e-3, 1e-3, 1e-3, 0.01 + 0.001 * k])
        q = T["geometry_msgs/msg/Quaternion"](x=0.0, y=0.0, z=math.sin(yaw / 2), w=math.cos(yaw / 2))
        pose = T["geometry_msgs/msg/Pose"](
            position=T["geometry_msgs/msg/Point"](x=0.1 * k, y=0.0, z=0.0), orientation=q
        )
        odom = T[ODOM](
            header=header(k, t, "odom"),
            child_frame_id="base_link",
            pose=T["geometry_msgs/msg/PoseWithCovariance"](pose=pose, covariance=pose_cov.reshape(36)),
            twist=T["geometry_msgs/msg/TwistWithCovariance"](
                twist=T["geometry_msgs/msg/Twist"](linear=vec(vx, 0, 0), angular=vec(0, 0, wz)),
                covariance=odom_twist_cov.reshape(36),
            ),
        )
        out.append(("/odom", ODOM, t + 2_000_000, odom))

        if k < 40:
            cov = six([0.05, 0.05, 0.05, 0, 0, 0])
            cov[3, 3] = -1.0
            accel = T["geometry_msgs/msg/AccelWithCovariance"](
                accel=T["geometry_msgs/msg/Accel"](linear=vec(0.1, 0, 9.81), angular=vec(0, 0, 0)),
                covariance=cov.reshape(36),
            )
            msg = T[ACCEL](header=header(k, t, "imu_link"), accel=accel)
            out.append(("/imu/accel", ACCEL, t + 3_000_000, msg))

        if k < 30:
            cov = six([0.04, 0.04, 0.04, 0, 0, 0])
            if k >= 10:
                cov[0, 1] = cov[1, 0] = 0.003  # ρ = 1.9: not PSD
            twist = T["geometry_msgs/msg/TwistWithCovariance"](
                twist=T["geometry_msgs/msg/Twist"](linear=vec(vx, 0, 0), angular=vec(0, 0, wz)),
                covariance=cov.reshape(36),
            )
            msg = T[TWIST](header=header(k, t, "camera"), twist=twist)
            out.append(("/vo/twist", TWIST, t + 4_000_000, msg))
    out.sort(key=lambda m: m[2])
    return out


def main() -> None:
    root = Path(sys.argv[1])
    ts1 = get_typestore(Stores.ROS1_NOETIC)
    bag = root / "twist.bag"
    bag.unlink(missing_ok=True)
    with Writer1(bag) as w:
        conns = {}
        for topic, msgtype, t, msg in messages(ts1):
            if topic not in conns:
                conns[topic] = w.add_connection(topic, msgtype, typestore=ts1)
            w.write(conns[topic], t, ts1.serialize_ros1(msg, msgtype))
    ts2 = get_typestore(Stores.ROS2_HUMBLE)
    db3 = root / "twist_db3"
    shutil.rmtree(db3, ignore_errors=True)
    with Writer2(db3, version=9, storage_plugin=StoragePlugin.SQLITE3) as w:
        conns = {}
        for topic, msgtype, t, msg in messages(ts2):
            if topic not in conns:
                conns[topic] = w.add_connection(topic, msgtype, typestore=ts2)
            w.write(conns[topic], t, ts2.serialize_cdr(msg, msgtype))


if __name__ == "__main__":
    main()
