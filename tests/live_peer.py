#!/usr/bin/env python3
"""A real Foxglove WebSocket server publishing scripted robot topics, for tests/live_ws.rs.

Runs in the pinned virtualenv that .ci/live-peer-venv creates (foxglove-sdk, foxglove-websocket,
rosbags). Serves on 127.0.0.1 only, on a port the OS picks, and prints one JSON line on stdout:
{"port": P, "messages": N} (N: the messages it will publish on the expected topics). Then:

1. advertises ROS 2 (`cdr`) and ROS 1 (`ros1`) channels, each message serialised by rosbags
   (not by posecov): a good EKF, NaN, a constant covariance while moving, a non-PSD covariance,
   a frozen stamp, and a reference topic (PoseStamped);
2. waits until the server reports that a client subscribed to every expected topic (the SDK
   server's `on_subscribe`, the legacy server's listener): no sleep is synchronisation; after
   --wait seconds without them it publishes anyway (to whoever is subscribed);
3. publishes every message once, paced (1 ms apart, or spread over --span seconds; far below the SDK server's 1024-message
   backlog), writing the same bytes with the same log time to --mcap (the Foxglove SDK's MCAP
   writer), then closes the MCAP and prints {"sent": N};
4. exits when the client has unsubscribed from every expected topic (or after --wait seconds).

--server sdk: the Foxglove SDK's server (foxglove.sdk.v1, the server code foxglove_bridge links);
--server legacy: PyPI foxglove-websocket (foxglove.websocket.v1, as older and ROS 1 bridges).
"""

import argparse
import asyncio
import json
import math
import sys
import threading
import time

import foxglove
from rosbags.typesys import Stores, get_typestore

ROS2 = get_typestore(Stores.ROS2_HUMBLE)
ROS1 = get_typestore(Stores.ROS1_NOETIC)
T0_NS = 1_700_000_000 * 10**9
STEP_NS = 100_000_000  # 10 Hz
COUNT = 30


def ros_time(store, ns):
    return store.types["builtin_interfaces/msg/Time"](sec=ns // 10**9, nanosec=ns % 10**9)


def header(store, ns, frame, ros1):
    h = store.types["std_msgs/msg/Header"]
    if ros1:
        return h(seq=0, stamp=ros_time(store, ns), frame_id=frame)
    return h(stamp=ros_time(store, ns), frame_id=frame)


def pose(store, x, yaw):
    t = store.types
    return t["geometry_msgs/msg/Pose"](
        position=t["geometry_msgs/msg/Point"](x=x, y=0.5 * x, z=0.0),
        orientation=t["geometry_msgs/msg/Quaternion"](
            x=0.0, y=0.0, z=math.sin(yaw / 2), w=math.cos(yaw / 2)
        ),
    )


def diag(values):
    import numpy as np

    c = np.zeros(36)
    for i, v in enumerate(values):
        c[7 * i] = v
    return c


def odometry(store, ros1, ns, x, cov):
    import numpy as np

    t = store.types
    twist = t["geometry_msgs/msg/Twist"](
        linear=t["geometry_msgs/msg/Vector3"](x=1.0, y=0.0, z=0.0),
        angular=t["geometry_msgs/msg/Vector3"](x=0.0, y=0.0, z=0.1),
    )
    return t["nav_msgs/msg/Odometry"](
        header=header(store, ns, "odom", ros1),
        child_frame_id="base_link",
        pose=t["geometry_msgs/msg/PoseWithCovariance"](pose=pose(store, x, 0.1 * x), covariance=cov),
        twist=t["geometry_msgs/msg/TwistWithCovariance"](twist=twist, covariance=np.full(36, 0.0) + diag([0.01] * 6)),
    )


def pose_cov(store, ros1, ns, x, cov):
    t = store.types
    return t["geometry_msgs/msg/PoseWithCovarianceStamped"](
        header=header(store, ns, "map", ros1),
        pose=t["geometry_msgs/msg/PoseWithCovariance"](pose=pose(store, x, 0.1 * x), covariance=cov),
    )


def script():
    """Every topic: (name, encoding, schema name, messages as (log time, bytes))."""
    topics = []

    def growing(i):
        s = 0.01 + 0.002 * i
        return diag([s, s, 1e-6 + s, 1e-4, 1e-4, 0.001 + 0.0005 * i])

    def add(topic, encoding, typename, build):
        store = ROS1 if encoding == "ros1" else ROS2
        messages = []
        for i in range(COUNT):
            ns = T0_NS + i * STEP_NS
            msg, stamp_ns = build(store, encoding == "ros1", i, ns)
            data = (
                store.serialize_ros1(msg, typename)
                if encoding == "ros1"
                else store.serialize_cdr(msg, typename)
            )
            messages.append((ns, bytes(data)))
        name = typename.replace("/msg/", "/") if encoding == "ros1" else typename
        schema, _ = store.generate_msgdef(typename, ros_version=1 if encoding == "ros1" else 2)
        topics.append((topic, encoding, name, schema, messages))

    # A good EKF (ROS 2): σ grows steadily while the robot drives 0.1 m a message.
    add("/odometry/filtered", "cdr", "nav_msgs/msg/Odometry",
        lambda s, r, i, ns: (odometry(s, r, ns, 0.1 * i, growing(i)), ns))

    # NaN in the covariance of message 7 (ROS 2).
    def nan(s, r, i, ns):
        c = growing(i)
        if i == 7:
            c[0] = float("nan")
        return odometry(s, r, ns, 0.1 * i, c), ns

    add("/odom_nan", "cdr", "nav_msgs/msg/Odometry", nan)

    # The same covariance while driving 2.9 m (ROS 1 wheel odometry): constant.
    add("/wheel/odom", "ros1", "nav_msgs/msg/Odometry",
        lambda s, r, i, ns: (odometry(s, r, ns, 0.1 * i, diag([0.05, 0.05, 1e-6, 1e-6, 1e-6, 0.02])), ns))

    # Not positive semi-definite at message 4 (ROS 1 AMCL).
    def not_psd(s, r, i, ns):
        c = growing(i)
        if i == 4:
            c[1] = c[6] = 1.0
        return pose_cov(s, r, ns, 0.1 * i, c), ns

    add("/amcl_pose", "ros1", "geometry_msgs/msg/PoseWithCovarianceStamped", not_psd)

    # A frozen stamp from message 10 on (ROS 2).
    add("/frozen", "cdr", "geometry_msgs/msg/PoseWithCovarianceStamped",
        lambda s, r, i, ns: (pose_cov(s, r, min(ns, T0_NS + 10 * STEP_NS), 0.1 * i, growing(i)), ns))

    # The reference (ROS 2 PoseStamped): the good EKF's path, 2 cm off.
    def truth(s, r, i, ns):
        t = s.types
        p = pose(s, 0.1 * i + 0.02, 0.1 * 0.1 * i)
        return t["geometry_msgs/msg/PoseStamped"](header=header(s, ns, "odom", r), pose=p), ns

    add("/ground_truth", "cdr", "geometry_msgs/msg/PoseStamped", truth)
    return topics


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--server", choices=["sdk", "legacy"], default="sdk")
    ap.add_argument("--mcap", required=True, help="write the published messages here")
    ap.add_argument("--expect", action="append", default=[],
                    help="topic the client must subscribe before publishing (repeatable; default all)")
    ap.add_argument("--wait", type=float, default=20.0, help="seconds to wait for subscriptions")
    ap.add_argument("--span", type=float, default=0.0,
                    help="spread the publishing over this many seconds (default: 1 ms apart)")
    args = ap.parse_args()
    topics = script()
    expected = set(args.expect or [t[0] for t in topics])
    total = sum(len(t[4]) for t in topics if t[0] in expected)
    # The MCAP: the SDK's writer in a context of its own (for the SDK server, the same context
    # feeds the server: one log call, the same bytes and log time to both).
    context = foxglove.Context()
    writer = foxglove.open_mcap(args.mcap, allow_overwrite=True, context=context)
    channels = {}
    for topic, encoding, name, schema, _ in topics:
        channels[topic] = foxglove.Channel(
            topic,
            schema=foxglove.Schema(
                name=name,
                encoding="ros1msg" if encoding == "ros1" else "ros2msg",
                data=schema.encode(),
            ),
            message_encoding=encoding,
            context=context,
        )
    if args.server == "sdk":
        run_sdk(args, topics, channels, context, writer, expected, total)
    else:
        asyncio.run(run_legacy(args, topics, channels, writer, expected, total))


def say(obj):
    print(json.dumps(obj), flush=True)


def pause(args, topics):
    """Seconds between two messages: 1 ms, or `--span` over all of them."""
    count = sum(len(t[4]) for t in topics)
    return max(0.001, args.span / count) if args.span > 0 else 0.001


def paced(topics):
    """Every message in log-time order, interleaved across topics."""
    events = [(ns, topic, data) for topic, _, _, _, msgs in topics for ns, data in msgs]
    events.sort(key=lambda e: e[0])
    return events


def run_sdk(args, topics, channels, context, writer, expected, total):
    subscribed = set()
    lock = threading.Condition()

    class Listener(foxglove.ServerListener):
        def on_subscribe(self, client, channel):
            with lock:
                subscribed.add(channel.topic)
                lock.notify_all()

        def on_unsubscribe(self, client, channel):
            with lock:
                subscribed.discard(channel.topic)
                lock.notify_all()

    server = foxglove.start_server(
        host="127.0.0.1", port=0, server_listener=Listener(), context=context, name="posecov test peer"
    )
    say({"port": server.port, "messages": total, "subprotocol": "foxglove.sdk.v1"})
    with lock:
        lock.wait_for(lambda: expected <= subscribed, timeout=args.wait)
    sent = 0
    for ns, topic, data in paced(topics):
        channels[topic].log(data, log_time=ns)
        sent += topic in expected
        time.sleep(pause(args, topics))
    writer.close()
    say({"sent": sent})
    with lock:
        lock.wait_for(lambda: not (expected & subscribed), timeout=args.wait)
    server.stop()


async def run_legacy(args, topics, channels, writer, expected, total):
    from foxglove_websocket.server import FoxgloveServer, FoxgloveServerListener

    subscribed = set()
    changed = asyncio.Event()
    by_id = {}

    class Listener(FoxgloveServerListener):
        def on_subscribe(self, server, channel_id):
            subscribed.add(by_id[channel_id])
            changed.set()

        def on_unsubscribe(self, server, channel_id):
            subscribed.discard(by_id[channel_id])
            changed.set()

    async def until(condition):
        deadline = time.monotonic() + args.wait
        while not condition() and time.monotonic() < deadline:
            changed.clear()
            try:
                await asyncio.wait_for(changed.wait(), timeout=deadline - time.monotonic())
            except asyncio.TimeoutError:
                break

    async with FoxgloveServer("127.0.0.1", 0, "posecov test peer (legacy)") as server:
        server.set_listener(Listener())
        ws = await server.wait_opened()
        port = ws.sockets[0].getsockname()[1]
        ids = {}
        for topic, encoding, name, schema, _ in topics:
            cid = await server.add_channel({
                "topic": topic,
                "encoding": encoding,
                "schemaName": name,
                "schema": schema,
                "schemaEncoding": "ros1msg" if encoding == "ros1" else "ros2msg",
            })
            ids[topic] = cid
            by_id[cid] = topic
        say({"port": port, "messages": total, "subprotocol": "foxglove.websocket.v1"})
        await until(lambda: expected <= subscribed)
        sent = 0
        for ns, topic, data in paced(topics):
            await server.send_message(ids[topic], ns, data)
            channels[topic].log(data, log_time=ns)
            sent += topic in expected
            await asyncio.sleep(pause(args, topics))
        writer.close()
        say({"sent": sent})
        await until(lambda: not (expected & subscribed))


if __name__ == "__main__":
    sys.exit(main())
