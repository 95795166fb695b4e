"""Check a fleet's robot logs on a Dask cluster: one log per task, with the posecov wheel.

    python fleet_dask.py LOGS_ROOT [--out fleet.jsonl] [--workers 2] [--scheduler ADDRESS]
                         [--dashboard] [--samples N] [--allow CLASS ...]

Every robot log under LOGS_ROOT (a directory tree: in each directory the ROS 1 bags, MCAP
files, ROS 2 .db3 files and ROS 2 bag directories, as ``posecov report DIR`` finds them) is
one task. A task runs ``posecov.report`` and ``posecov.check`` on its log and returns

* the log's line of JSON Lines, the same object ``posecov report DIR --json`` prints for it
  (``{"error": {...}, "scenario": LOG}`` when the log cannot be read: a damaged log yields its
  error line and the run goes on), and
* check's verdict: the line ``posecov check`` prints, its exit code and the defects.

The lines are written to ``--out`` as they finish (like the CLI, in finishing order; every
line names its ``scenario``), then a summary table is printed: the verdict per log and the
defects by class and topic. The exit code is the worst log's, as ``posecov check``'s.

Without ``--scheduler`` the script starts a ``distributed.LocalCluster`` of ``--workers``
worker processes (one thread each: posecov parallelises inside a log) with the dashboard off
(``--dashboard``: on 127.0.0.1:8787 only). With ``--scheduler tcp://HOST:8786`` it joins a
running cluster; then every worker needs the posecov wheel and the logs at the same path
(shared or object storage, see docs/fleet.md).
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
from collections import defaultdict
from typing import Any, Dict, List, Tuple


def find_logs(root: str) -> List[str]:
    """Every robot log under ``root``: per directory, what ``posecov report DIR`` reads (the
    CLI's own expansion, ``posecov.expand``), then its subdirectories that are not ROS 2 bag
    directories, in name order."""
    import posecov

    logs: List[str] = []
    for directory, subdirs, _ in os.walk(root):
        subdirs[:] = sorted(d for d in subdirs if not os.path.isfile(os.path.join(directory, d, "metadata.yaml")))
        try:
            logs.extend(posecov.expand(directory))
        except posecov.PosecovError:
            pass  # a directory with no log of its own
    if os.path.isfile(os.path.join(root, "metadata.yaml")):
        logs = [root]
    return logs


def check_one(log: str, overrides: Dict[str, Any], allow: List[str]) -> Tuple[Dict[str, Any], Dict[str, Any]]:
    """One task: the log's report line and check's verdict. Runs on a worker."""
    import posecov

    try:
        line = posecov.report(log, **overrides)
    except posecov.PosecovError as e:
        # The line `posecov report DIR --json` prints for an input that fails.
        error = {"error": e.details, "scenario": log}
        text = str(e)
        reason = text[len(log) + 2 :] if text.startswith(f"{log}: ") else text
        return error, {"line": f"{log}: error: {reason}", "exit_code": e.exit_code, "defects": []}
    try:
        verdict = posecov.check(log, allow=allow, **overrides)
    except posecov.PosecovError as e:
        verdict = {"line": f"{log}: error: {e}", "exit_code": e.exit_code, "defects": []}
    return line, verdict


def summary(results: List[Tuple[Dict[str, Any], Dict[str, Any]]]) -> str:
    """The verdict per log, then defects and notes by class, issue and topic (from the
    reports' `topics[].health`), then the logs that could not be read."""
    out = ["verdict per log:"]
    for line, verdict in sorted(results, key=lambda r: r[0]["scenario"]):
        out.append(f"  [{verdict['exit_code']}] {verdict['line']}")
    table: Dict[Tuple[str, str, str], List[int]] = defaultdict(lambda: [0, 0])
    errors = 0
    for line, _ in results:
        if "error" in line:
            errors += 1
            continue
        for topic in line.get("topics", []):
            for issue, found in topic.get("health", {}).items():
                row = table[(found["class"], issue, topic["name"])]
                row[0] += 1
                row[1] += found["count"]
    out.append("")
    out.append(f"{'class':<8} {'issue':<24} {'topic':<32} {'logs':>5} {'messages':>9}")
    for (cls, issue, topic), (logs, messages) in sorted(table.items()):
        out.append(f"{cls:<8} {issue:<24} {topic:<32} {logs:>5} {messages:>9}")
    out.append("")
    defective = sum(1 for _, v in results if v["exit_code"] == 1)
    out.append(f"{len(results)} logs: {len(results) - defective - errors} ok, {defective} with defects, {errors} unreadable")
    return "\n".join(out)


def run(root: str, out_path: str, workers: int, scheduler: str | None, dashboard: bool,
        overrides: Dict[str, Any], allow: List[str]) -> int:
    from distributed import Client, LocalCluster, as_completed

    logs = find_logs(root)
    if not logs:
        print(f"{root}: no robot log (.bag, .mcap, .db3, or a ROS 2 bag directory) in this tree", file=sys.stderr)
        return 2
    started = time.perf_counter()
    if scheduler:
        cluster = None
        client = Client(scheduler)
    else:
        cluster = LocalCluster(
            n_workers=workers,
            threads_per_worker=1,
            processes=True,
            host="127.0.0.1",
            dashboard_address="127.0.0.1:8787" if dashboard else None,
        )
        client = Client(cluster)
    results = []
    worst = 0
    try:
        futures = [client.submit(check_one, log, overrides, allow, key=f"posecov-{i}", pure=False)
                   for i, log in enumerate(logs)]
        with open(out_path, "w", encoding="utf-8") as out:
            for future in as_completed(futures):
                line, verdict = future.result()
                out.write(json.dumps(line, ensure_ascii=False, separators=(",", ":")) + "\n")
                out.flush()
                results.append((line, verdict))
                worst = max(worst, verdict["exit_code"])
    finally:
        client.close()
        if cluster is not None:
            cluster.close()
    print(summary(results))
    print(f"{len(logs)} logs on {workers if not scheduler else 'the cluster'} workers in "
          f"{time.perf_counter() - started:.1f} s; lines in {out_path}", file=sys.stderr)
    return worst


def main(argv: List[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("root", help="a directory tree of robot logs")
    p.add_argument("--out", default="fleet.jsonl", help="the JSON Lines file (default fleet.jsonl)")
    p.add_argument("--workers", type=int, default=2, help="LocalCluster worker processes (default 2)")
    p.add_argument("--scheduler", help="a running Dask scheduler, e.g. tcp://10.0.0.5:8786")
    p.add_argument("--dashboard", action="store_true", help="serve the dashboard on 127.0.0.1:8787")
    p.add_argument("--samples", type=int, help="as posecov's --samples")
    p.add_argument("--seed", type=int, help="as posecov's --seed")
    p.add_argument("--every", type=int, help="as posecov's --every")
    p.add_argument("--topic", action="append", help="as posecov's --topic (repeatable)")
    p.add_argument("--ros-reading", dest="ros_reading", help="as posecov's --ros-reading")
    p.add_argument("--allow", action="append", default=[], help="as posecov check's --allow")
    a = p.parse_args(argv)
    overrides = {k: v for k, v in [("samples", a.samples), ("seed", a.seed), ("every", a.every),
                                   ("topic", a.topic), ("ros_reading", a.ros_reading)] if v is not None}
    return run(a.root, a.out, a.workers, a.scheduler, a.dashboard, overrides, a.allow)


if __name__ == "__main__":
    sys.exit(main())
