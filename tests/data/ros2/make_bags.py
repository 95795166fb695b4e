"""Writes the ROS 2 bags under tests/data/ros2/ with PyPI `rosbags` (0.11.9), an independent
writer of rosbag2 SQLite bags and MCAP files. Every message is synthetic (this script makes
it: a robot driving a slow arc, seeded), so the bags carry no one else's data.

Usage (from the repository root, in a virtualenv with `pip install rosbags==0.11.9`):
    python tests/data/ros2/make_bags.py tests/data/ros2

Writes, from the same messages:
  arc_v9/          rosbag2 version 9, SQLite storage, no compression (one .db3)
  arc_v8_split/    version 8, the same messages split over two .db3 files (in order)
  arc_zstd_file/   version 9, zstd compression of the whole file (arc_zstd_file_0.db3.zstd)
  arc_zstd_message/ version 9, zstd compression of every message
  arc_humble/      Humble's layout: version 5 (the v8 bag converted: no message_definitions
                   table, no type_description_hash column, SQLite schema version 3)
  arc.mcap         the same messages in MCAP (rosbags' MCAP storage), for the same report
Topics: /odom (nav_msgs/msg/Odometry, 100 messages), /amcl_pose
(geometry_msgs/msg/PoseWithCovarianceStamped, 25), /truth (geometry_msgs/msg/PoseStamped,
100: the NEES reference), /imu (sensor_msgs/msg/Imu, 20: a type posecov skips).
"""

import math
import shutil
import sqlite3
import sys
from io import StringIO
from pathlib import Path

from rosbags.rosbag2 import Writer
from rosbags.rosbag2.enums import CompressionFormat, CompressionMode, StoragePlugin
from rosbags.typesys import Stores, get_typestore
from ruamel.yaml import YAML

TS = get_typestore(Stores.ROS2_HUMBLE)
T = TS.types
START_NS = 1_700_000_000_000_000_000
ODOM = "nav_msgs/msg/Odometry"
AMCL = "geometry_msgs/msg/PoseWithCovarianceStamped"
TRUTH = "geometry_msgs/msg/PoseStamped"
IMU = "sensor_msgs/msg/Imu"


def header(t_ns: int, frame: str):
    return T["std_msgs/msg/Header"](
        stamp=T["builtin_interfaces/msg/Time"](sec=t_ns // 10**9, nanosec=t_ns % 10**9),
        frame_id=frame,
    )


def pose(k: int, noise: float):
    """The robot at step k on a slow arc (0.1 m and 0.02 rad per step), nudged by `noise`."""
    yaw = 0.02 * k + noise
    x = 5.0 * math.sin(0.02 * k) + noise
    y = 5.0 * (1.0 - math.cos(0.02 * k)) - noise
    q = T["geometry_msgs/msg/Quaternion"](x=0.0, y=0.0, z=math.sin(yaw / 2), w=math.cos(yaw / 2))
    return T["geometry_msgs/msg/Pose"](position=T["geometry_msgs/msg/Point"](x=x, y=y, z=0.0), orientation=q)


def covariance(k: int):
    """A planar covariance growing with k: x, y correlated, yaw; z, roll, pitch 1e-6."""
    import numpy as np

    s = 1.0 + 0.05 * k
    c = np.zeros(36)
    c[0], c[7], c[1], c[6] = 0.01 * s, 0.02 * s, 0.004 * s, 0.004 * s
    c[14] = c[21] = c[28] = 1e-6
    c[35] = 0.003 * s
    return c


def messages():
    """(topic, type, log time ns, message) in recording order."""
    import numpy as np

    rng = np.random.default_rng(7)
    out = []
    for k in range(100):
        t = START_NS + k * 50_000_000
        truth = T[TRUTH](header=header(t, "odom"), pose=pose(k, 0.0))
        out.append(("/truth", TRUTH, t + 1_000_000, truth))
        odom = T[ODOM](
            header=header(t, "odom"),
            child_frame_id="base_link",
            pose=T["geometry_msgs/msg/PoseWithCovariance"](pose=pose(k, 0.05 * rng.standard_normal()), covariance=covariance(k)),
            twist=T["geometry_msgs/msg/TwistWithCovariance"](
                twist=T["geometry_msgs/msg/Twist"](
                    linear=T["geometry_msgs/msg/Vector3"](x=2.0, y=0.0, z=0.0),
                    angular=T["geometry_msgs/msg/Vector3"](x=0.0, y=0.0, z=0.4),
                ),
                covariance=np.eye(6).reshape(36) * 0.01,
            ),
        )
        out.append(("/odom", ODOM, t + 2_000_000, odom))
        if k % 4 == 0:
            amcl = T[AMCL](
                header=header(t, "odom"),
                pose=T["geometry_msgs/msg/PoseWithCovariance"](pose=pose(k, 0.03 * rng.standard_normal()), covariance=covariance(k) * 0.5),
            )
            out.append(("/amcl_pose", AMCL, t + 3_000_000, amcl))
        if k % 5 == 0:
            imu = T[IMU](
                header=header(t, "imu_link"),
                orientation=T["geometry_msgs/msg/Quaternion"](x=0.0, y=0.0, z=0.0, w=1.0),
                orientation_covariance=np.array([-1.0] + [0.0] * 8),
                angular_velocity=T["geometry_msgs/msg/Vector3"](x=0.0, y=0.0, z=0.4),
                angular_velocity_covariance=np.eye(3).reshape(9) * 1e-4,
                linear_acceleration=T["geometry_msgs/msg/Vector3"](x=0.0, y=0.0, z=9.81),
                linear_acceleration_covariance=np.eye(3).reshape(9) * 1e-2,
            )
            out.append(("/imu", IMU, t + 4_000_000, imu))
    return out


def write(path: Path, version: int, plugin=StoragePlugin.SQLITE3, compression=None, part=None):
    """One bag of every message (or of `part`, a slice of them)."""
    msgs = messages()
    if part is not None:
        msgs = msgs[part]
    writer = Writer(path, version=version, storage_plugin=plugin)
    if compression is not None:
        writer.set_compression(compression, CompressionFormat.ZSTD)
    with writer:
        conns = {}
        for topic, msgtype in [("/truth", TRUTH), ("/odom", ODOM), ("/amcl_pose", AMCL), ("/imu", IMU)]:
            conns[topic] = writer.add_connection(topic, msgtype, typestore=TS)
        for topic, msgtype, t, msg in msgs:
            writer.write(conns[topic], t, TS.serialize_cdr(msg, msgtype))


def yaml():
    y = YAML(typ="safe")
    y.default_flow_style = False
    return y


def split(out: Path, work: Path) -> None:
    """Two bags of the first and second half, joined as one split bag: both .db3 files in one
    directory, in order, under one metadata.yaml (as rosbag2's --max-bag-size writes)."""
    n = len(messages())
    write(work / "a", 8, part=slice(0, n // 2))
    write(work / "b", 8, part=slice(n // 2, n))
    out.mkdir()
    names = []
    for i, part in enumerate(["a", "b"]):
        name = f"{out.name}_{i}.db3"
        shutil.copy(work / part / f"{part}.db3", out / name)
        names.append(name)
    ma = yaml().load((work / "a" / "metadata.yaml").read_text())
    mb = yaml().load((work / "b" / "metadata.yaml").read_text())
    info, other = ma["rosbag2_bagfile_information"], mb["rosbag2_bagfile_information"]
    info["relative_file_paths"] = names
    info["files"][0]["path"] = names[0]
    other["files"][0]["path"] = names[1]
    info["files"].append(other["files"][0])
    info["message_count"] += other["message_count"]
    for t, u in zip(info["topics_with_message_count"], other["topics_with_message_count"]):
        t["message_count"] += u["message_count"]
    end = other["starting_time"]["nanoseconds_since_epoch"] + other["duration"]["nanoseconds"]
    info["duration"]["nanoseconds"] = end - info["starting_time"]["nanoseconds_since_epoch"]
    s = StringIO()
    yaml().dump(ma, s)
    (out / "metadata.yaml").write_text(s.getvalue())


def humble(src: Path, out: Path) -> None:
    """The version 8 bag in Humble's layout: metadata version 5 (no ros_distro, custom_data or
    type_description_hash), SQLite schema version 3 (no message_definitions table, no
    type_description_hash column in topics)."""
    out.mkdir()
    db = out / f"{out.name}_0.db3"
    shutil.copy(src / f"{src.name}.db3", db)
    meta = yaml().load((src / "metadata.yaml").read_text())
    info = meta["rosbag2_bagfile_information"]
    info["version"] = 5
    for key in ["ros_distro", "custom_data"]:
        info.pop(key, None)
    for t in info["topics_with_message_count"]:
        t["topic_metadata"].pop("type_description_hash", None)
    info["relative_file_paths"] = [db.name]
    info["files"][0]["path"] = db.name
    s = StringIO()
    yaml().dump(meta, s)
    (out / "metadata.yaml").write_text(s.getvalue())
    inner = StringIO()
    yaml().dump(info, inner)
    con = sqlite3.connect(db)
    con.executescript(
        """
        DROP TABLE message_definitions;
        ALTER TABLE topics DROP COLUMN type_description_hash;
        UPDATE schema SET schema_version = 3, ros_distro = 'humble';
        DELETE FROM metadata;
        """
    )
    con.execute("INSERT INTO metadata (metadata_version, metadata) VALUES (5, ?)", (inner.getvalue().strip(),))
    con.commit()
    con.execute("VACUUM")
    con.close()


def main() -> None:
    root = Path(sys.argv[1])
    work = root / "_work"
    shutil.rmtree(work, ignore_errors=True)
    work.mkdir(parents=True)
    for name in ["arc_v9", "arc_v8_split", "arc_zstd_file", "arc_zstd_message", "arc_humble", "arc.mcap"]:
        p = root / name
        if p.is_dir():
            shutil.rmtree(p)
        elif p.exists():
            p.unlink()
    write(root / "arc_v9", 9)
    split(root / "arc_v8_split", work)
    write(root / "arc_zstd_file", 9, compression=CompressionMode.FILE)
    write(root / "arc_zstd_message", 9, compression=CompressionMode.MESSAGE)
    write(work / "arc_v8", 8)
    humble(work / "arc_v8", root / "arc_humble")
    write(work / "arc_mcap", 9, plugin=StoragePlugin.MCAP)
    shutil.copy(work / "arc_mcap" / "arc_mcap.mcap", root / "arc.mcap")
    shutil.rmtree(work)


if __name__ == "__main__":
    main()
