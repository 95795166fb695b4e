"""Writes tests/data/navsat/navsat.bag (ROS 1) and navsat.mcap (ROS 2, CDR) with PyPI `rosbags`
(0.11.9), an independent writer of both: synthetic `sensor_msgs/NavSatFix` topics for the
message's `position_covariance_type` conventions. Every message is made here (seeded), so the
files carry no one else's data.

Usage (from the repository root, in a virtualenv with `pip install rosbags==0.11.9 numpy`):
    python tests/data/navsat/make_navsat.py tests/data/navsat

Topics (one fix a second from 1 700 000 000 s; a walk of about 60 m near 48.137° N, 11.575° E,
520 m; both files hold the same messages):
  /gps/fix           30 fixes, COVARIANCE_TYPE_KNOWN: σ east 1.0…1.6 m, σ north 1.2…1.9 m
                     (rising, then falling back), correlation 0.3, σ up 3 m
  /gps/unknown       20 fixes, COVARIANCE_TYPE_UNKNOWN, covariance all zero; message 5 has
                     status STATUS_NO_FIX
  /gps/approximated  10 fixes, COVARIANCE_TYPE_APPROXIMATED, diagonal from an HDOP of 1.2
                     (σ 1.2 × 2.5 m), constant
  /gps/diagonal_bad  10 fixes, COVARIANCE_TYPE_DIAGONAL_KNOWN with off-diagonal entries 0.5 m²
"""

import math
import sys
from pathlib import Path

import numpy as np
from rosbags.rosbag1 import Writer as Writer1
from rosbags.rosbag2 import StoragePlugin, Writer as Writer2
from rosbags.typesys import Stores, get_typestore

FIX = "sensor_msgs/msg/NavSatFix"
START_NS = 1_700_000_000 * 10**9
LAT0, LON0, H0 = 48.137, 11.575, 520.0
# WGS84 radii of curvature at LAT0 (meridian M, prime vertical N).
A, F = 6378137.0, 1 / 298.257223563
E2 = F * (2 - F)
W = 1 - E2 * math.sin(math.radians(LAT0)) ** 2
M, N = A * (1 - E2) / W**1.5, A / math.sqrt(W)


def geodetic(east: float, north: float, up: float):
    """The latitude, longitude and height of a point east/north/up of the origin (metres)."""
    lat = LAT0 + math.degrees(north / (M + H0))
    lon = LON0 + math.degrees(east / ((N + H0) * math.cos(math.radians(LAT0))))
    return lat, lon, H0 + up


def fix(T, t_ns, seq, status, position, cov, cov_type):
    lat, lon, h = position
    stamp = T["builtin_interfaces/msg/Time"](sec=t_ns // 10**9, nanosec=t_ns % 10**9)
    header = T["std_msgs/msg/Header"]
    # ROS 1's header has a sequence number, ROS 2's not.
    if "seq" in header.__dataclass_fields__:
        header = header(seq=seq, stamp=stamp, frame_id="gps_antenna")
    else:
        header = header(stamp=stamp, frame_id="gps_antenna")
    return T[FIX](
        header=header,
        status=T["sensor_msgs/msg/NavSatStatus"](status=status, service=1),
        latitude=lat,
        longitude=lon,
        altitude=h,
        position_covariance=np.array(cov, dtype=np.float64),
        position_covariance_type=cov_type,
    )


def messages(T):
    """(topic, log time ns, message) in log-time order."""
    rng = np.random.default_rng(145)
    out = []
    for k in range(30):
        t = START_NS + k * 10**9
        s = 0.5 * (1 - math.cos(2 * math.pi * k / 29))  # 0 → 1 → 0
        se, sn, su = 1.0 + 0.6 * s, 1.2 + 0.7 * s, 3.0
        c = 0.3 * se * sn
        cov = [se * se, c, 0.0, c, sn * sn, 0.0, 0.0, 0.0, su * su]
        east = 30 * math.sin(math.pi * k / 29) + se * rng.standard_normal()
        north = 2.0 * k + sn * rng.standard_normal()
        out.append(("/gps/fix", t, fix(T, t, k, 0, geodetic(east, north, 0.0), cov, 3)))
        if k < 20:
            status = -1 if k == 5 else 0
            p = geodetic(2.0 * k, 0.5 * k, 0.0)
            out.append(("/gps/unknown", t + 1000, fix(T, t, k, status, p, [0.0] * 9, 0)))
        if k < 10:
            v = (1.2 * 2.5) ** 2
            approx = [v, 0.0, 0.0, 0.0, v, 0.0, 0.0, 0.0, 4 * v]
            p = geodetic(-1.0 * k, 1.0 * k, 0.0)
            out.append(("/gps/approximated", t + 2000, fix(T, t, k, 1, p, approx, 1)))
            bad = [2.0, 0.5, 0.0, 0.5, 2.0, 0.0, 0.0, 0.0, 6.0]
            p = geodetic(1.0 * k, -1.0 * k, 0.0)
            out.append(("/gps/diagonal_bad", t + 3000, fix(T, t, k, 0, p, bad, 2)))
    return out


TOPICS = ["/gps/fix", "/gps/unknown", "/gps/approximated", "/gps/diagonal_bad"]


def main() -> None:
    out = Path(sys.argv[1])
    bag = out / "navsat.bag"
    bag.unlink(missing_ok=True)
    ts1 = get_typestore(Stores.ROS1_NOETIC)
    with Writer1(bag) as w:
        conns = {name: w.add_connection(name, FIX, typestore=ts1) for name in TOPICS}
        for topic, t, msg in messages(ts1.types):
            w.write(conns[topic], t, ts1.serialize_ros1(msg, FIX))
    # rosbag2 writes a directory; its one .mcap file is kept, the directory removed.
    ts2 = get_typestore(Stores.ROS2_HUMBLE)
    tmp = out / "navsat_mcap"
    if tmp.exists():
        for p in tmp.iterdir():
            p.unlink()
        tmp.rmdir()
    with Writer2(tmp, version=9, storage_plugin=StoragePlugin.MCAP) as w:
        conns = {name: w.add_connection(name, FIX, typestore=ts2) for name in TOPICS}
        for topic, t, msg in messages(ts2.types):
            w.write(conns[topic], t, ts2.serialize_cdr(msg, FIX))
    (out / "navsat.mcap").unlink(missing_ok=True)
    next(tmp.glob("*.mcap")).rename(out / "navsat.mcap")
    for p in tmp.iterdir():
        p.unlink()
    tmp.rmdir()


if __name__ == "__main__":
    main()
