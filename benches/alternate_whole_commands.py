#!/usr/bin/env python3
"""Issue 33 item 5, on a noisy machine: a graph's whole commands for two posecov binaries and
GTSAM's whole Python process, in alternating rounds (each round runs every command once, every
other round in reverse order), timed from outside; prints each command's median, min and max
wall seconds and its ratio to GTSAM's median. Single shots of a 0.2 s command move by ±25 % on
a shared machine; medians of alternating rounds compare two binaries side by side.

Usage: benches/alternate_whole_commands.py ROUNDS GRAPH.g2o NEW_BINARY [BEFORE_BINARY]
GTSAM's virtualenv: $POSECOV_GTSAM_VENV, else ~/.cache/posecov/gtsam-venv (benches/run_gtsam.sh
makes it).
"""
import os
import statistics
import subprocess
import sys
import tempfile
import time


def main():
    if len(sys.argv) not in (4, 5):
        sys.exit(__doc__)
    rounds, graph, binaries = int(sys.argv[1]), sys.argv[2], sys.argv[3:]
    venv = os.environ.get(
        "POSECOV_GTSAM_VENV", os.path.expanduser("~/.cache/posecov/gtsam-venv")
    )
    here = os.path.dirname(os.path.abspath(__file__))
    out = tempfile.mkdtemp()
    commands = []
    for k, binary in enumerate(binaries):
        name = "new" if k == 0 else "before"
        commands += [
            (f"{name} report", [binary, "report", graph, "--json"]),
            (f"{name} --save", [binary, graph, "--save", f"{out}/{name}.rrd"]),
            (f"{name} figure", [binary, "figure", graph, "-o", f"{out}/{name}.svg"]),
        ]
    gtsam = [f"{venv}/bin/python", f"{here}/gtsam_graphs.py", graph]
    commands.append(("gtsam", gtsam))
    env = dict(os.environ, OMP_NUM_THREADS="1")
    times = {name: [] for name, _ in commands}
    for r in range(rounds):
        for name, argv in commands if r % 2 == 0 else list(reversed(commands)):
            start = time.perf_counter()
            subprocess.run(argv, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, check=True)
            times[name].append(time.perf_counter() - start)
    reference = statistics.median(times["gtsam"])
    print(f"{os.path.basename(graph)}: {rounds} alternating rounds")
    for name, _ in commands:
        t = sorted(times[name])
        median = statistics.median(t)
        print(f"{name:15s} median {median:.3f} s  min {t[0]:.3f}  max {t[-1]:.3f}  × GTSAM {reference / median:.2f}")


if __name__ == "__main__":
    main()
