"""Writes tests/data/imu/imu_rep145.bag with PyPI `rosbags` (0.11.9), an independent writer of
ROS 1 bags: two synthetic `sensor_msgs/Imu` topics for REP 145's two conventions. Every message
is made here (seeded), so the bag carries no one else's data.

Usage (from the repository root, in a virtualenv with `pip install rosbags==0.11.9`):
    python tests/data/imu/make_imu.py tests/data/imu

Topics (stamps 0.01 s apart from 1 700 000 000 s):
  /imu/no_orientation  40 messages: orientation_covariance[0] = -1 ("not provided", a gyro and
                       accelerometer without an orientation filter); angular velocity σ 0.02 rad/s,
                       linear acceleration σ 0.05 m/s², diagonal and constant
  /imu/zeros           20 messages: all three covariances all zero ("unknown")
"""

import sys
from pathlib import Path

import numpy as np
from rosbags.rosbag1 import Writer
from rosbags.typesys import Stores, get_typestore

TS = get_typestore(Stores.ROS1_NOETIC)
T = TS.types
IMU = "sensor_msgs/msg/Imu"
START_NS = 1_700_000_000 * 10**9


def imu(t_ns: int, seq: int, orientation_cov, gyro_cov, accel_cov, rng):
    q = T["geometry_msgs/msg/Quaternion"](x=0.0, y=0.0, z=0.0, w=1.0)
    return T[IMU](
        header=T["std_msgs/msg/Header"](
            seq=seq,
            stamp=T["builtin_interfaces/msg/Time"](sec=t_ns // 10**9, nanosec=t_ns % 10**9),
            frame_id="imu_link",
        ),
        orientation=q,
        orientation_covariance=np.array(orientation_cov, dtype=np.float64),
        angular_velocity=T["geometry_msgs/msg/Vector3"](x=0.0, y=0.0, z=0.3 + 0.02 * rng.standard_normal()),
        angular_velocity_covariance=np.array(gyro_cov, dtype=np.float64),
        linear_acceleration=T["geometry_msgs/msg/Vector3"](x=0.1, y=0.0, z=9.81 + 0.05 * rng.standard_normal()),
        linear_acceleration_covariance=np.array(accel_cov, dtype=np.float64),
    )


def main() -> None:
    out = Path(sys.argv[1]) / "imu_rep145.bag"
    out.unlink(missing_ok=True)
    rng = np.random.default_rng(145)
    not_provided = [-1.0] + [0.0] * 8
    gyro = list((np.eye(3) * 0.02**2).reshape(9))
    accel = list((np.eye(3) * 0.05**2).reshape(9))
    zeros = [0.0] * 9
    with Writer(out) as w:
        a = w.add_connection("/imu/no_orientation", IMU, typestore=TS)
        b = w.add_connection("/imu/zeros", IMU, typestore=TS)
        for k in range(40):
            t = START_NS + k * 10_000_000
            msg = imu(t, k, not_provided, gyro, accel, rng)
            w.write(a, t + 1_000_000, TS.serialize_ros1(msg, IMU))
            if k % 2 == 0:
                msg = imu(t, k // 2, zeros, zeros, zeros, rng)
                w.write(b, t + 2_000_000, TS.serialize_ros1(msg, IMU))


if __name__ == "__main__":
    main()
