"""The Python package beside pytransform3d, and the fleet on Dask beside the CLI (issue 34).

    python benches/python_bench.py compounding [--steps 100] [--repeats 30]
    python benches/python_bench.py overhead [--calls 200000]
    python benches/python_bench.py fleet --posecov BIN --data tests/data [--copies 20] [--workers 2]

Run through benches/run_python.sh, which builds the release wheel into the bench's own
virtualenv (pytransform3d lives there only, never in CI's) and runs the Rust side of the
overhead comparison in criterion (benches/compose.rs) in the same run.

compounding: Barfoot & Furgale's compounding workload in the shape of pytransform3d's own example
("Concatenate Uncertain Transforms", examples/plots/plot_concatenate_uncertain_transforms.py): a constant uncertain motion T_vel with Sigma_vel, compounded onto the pose `steps`
times, T_k+1 = T_vel T_k, fourth order. pytransform3d's
`concat_globally_uncertain_transforms(mean_A2B, cov_A2B, mean_B2C, cov_B2C)` against
`UncertainPose.compose(method="fourth_order")` with left (global) inputs in rotation-first
order, on the same inputs; the final means and covariances are checked equal before timing.
Best of `repeats` whole chains each.

overhead: one first-order `compose` of two SE(3) poses with covariance from Python
(`a.compose(b)`: argument checks, the Rust call, a new `UncertainPose`), and building an
`UncertainPose` from NumPy arrays; ns per call, best of five timeit runs.

fleet: a directory tree of generated logs (the committed logs copied `copies` times into
robot_NN/ directories) through python/examples/fleet_dask.py on a LocalCluster of `workers`
processes (each task runs `posecov.report` and `posecov.check` on its log), and through the
CLI doing the same work, `posecov check DIR...` plus `posecov report DIR... --json` (one process
each, logs in parallel); every process timed from outside, best of three. The engine's
overhead is their difference; the per-log cost is the CLI's time over the logs.
"""

from __future__ import annotations

import argparse
import os
import shutil
import subprocess
import sys
import tempfile
import time
import timeit

import numpy as np


def compounding(steps: int, repeats: int) -> None:
    from pytransform3d import transformations as pt
    from pytransform3d.uncertainty import concat_globally_uncertain_transforms

    import posecov

    # As in pytransform3d's example: constant motion along x (1 m and 0.05 rad of yaw per step)
    # with noise mostly in the heading, rotation first [omega; v], from a certain start.
    mean_vel = pt.transform_from_exponential_coordinates([0.0, 0.0, 0.05, 1.0, 0.0, 0.0])
    cov_vel = np.diag([1e-4, 1e-4, 3e-3, 2e-2, 1e-4, 1e-4])
    mean0, cov0 = np.eye(4), np.zeros((6, 6))

    def theirs():
        mean, cov = mean0, cov0
        for _ in range(steps):
            mean, cov = concat_globally_uncertain_transforms(mean, cov, mean_vel, cov_vel)
        return mean, cov

    vel = posecov.UncertainPose("SE3", mean_vel, cov_vel, side="left", order="rotation_first")
    start = posecov.UncertainPose("SE3", mean0, cov0, side="left", order="rotation_first")

    def ours():
        x = start
        for _ in range(steps):
            x = vel.compose(x, method="fourth_order")
        return x.mean, x.cov_in("rotation_first")

    (m1, c1), (m2, c2) = theirs(), ours()
    np.testing.assert_allclose(m2, m1, atol=1e-9)
    np.testing.assert_allclose(c2, c1, rtol=1e-7, atol=1e-12)
    t_theirs = min(timeit.repeat(theirs, number=1, repeat=repeats))
    t_ours = min(timeit.repeat(ours, number=1, repeat=repeats))
    print(f"compounding steps={steps} (fourth order, results equal to 1e-7)")
    print(f"  pytransform3d concat_globally_uncertain_transforms: {t_theirs * 1e3:.3f} ms "
          f"({t_theirs / steps * 1e6:.1f} us/step)")
    print(f"  posecov UncertainPose.compose(fourth_order):        {t_ours * 1e3:.3f} ms "
          f"({t_ours / steps * 1e6:.2f} us/step)")
    print(f"  ratio: {t_theirs / t_ours:.1f}x")


def overhead(calls: int) -> None:
    import posecov

    rng = np.random.default_rng(7)
    a = rng.normal(size=(6, 6)) * 0.05
    b = rng.normal(size=(6, 6)) * 0.05
    cov_a, cov_b = a @ a.T + np.eye(6) * 1e-4, b @ b.T + np.eye(6) * 1e-4
    mean_a = posecov.SE3.exp([1.0, 2.0, 0.5, 0.1, -0.2, 0.7])
    mean_b = posecov.SE3.exp([0.3, -1.0, 0.2, 0.05, 0.1, -0.3])
    x = posecov.UncertainPose("SE3", mean_a, cov_a)
    y = posecov.UncertainPose("SE3", mean_b, cov_b)
    per_call = lambda stmt: min(timeit.repeat(stmt, number=calls, repeat=5)) / calls * 1e9
    compose = per_call(lambda: x.compose(y))
    compose4 = per_call(lambda: x.compose(y, method="fourth_order"))
    build = per_call(lambda: posecov.UncertainPose("SE3", mean_a, cov_a))
    print(f"overhead calls={calls}")
    print(f"  python compose first order (SE3, with covariance): {compose:.0f} ns/call")
    print(f"  python compose fourth order (SE3):                 {compose4:.0f} ns/call")
    print(f"  python UncertainPose(SE3) from arrays:             {build:.0f} ns/call")


def make_fleet(root: str, data: str, copies: int) -> int:
    """`copies` robot directories, each with the committed logs that read cleanly or with
    defects (ROS 1 bag, MCAP, ROS 2 bag directory, .db3). Returns the number of logs."""
    logs = [
        ("robot_localization/test2.bag", "jackal.bag"),
        ("mcap/amcl_tf.mcap", "amcl_tf.mcap"),
        ("mcap/health_cases.mcap", "health_cases.mcap"),
        ("ros2/arc_humble/arc_humble_0.db3", "humble.db3"),
    ]
    n = 0
    for k in range(copies):
        d = os.path.join(root, f"robot_{k:02}")
        os.makedirs(d)
        for src, name in logs:
            shutil.copy(os.path.join(data, src), os.path.join(d, name))
            n += 1
        shutil.copytree(os.path.join(data, "ros2/arc_v9"), os.path.join(d, "arc_v9"))
        n += 1
    return n


def wall(cmd, repeats: int = 3) -> float:
    best = float("inf")
    for _ in range(repeats):
        t = time.perf_counter()
        done = subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        best = min(best, time.perf_counter() - t)
        if done.returncode not in (0, 1):  # 1: a defect was found, as expected of these logs
            raise SystemExit(f"{cmd[0]} exited {done.returncode}")
    return best


def fleet(posecov_bin: str, data: str, copies: int, workers: int) -> None:
    here = os.path.dirname(os.path.abspath(__file__))
    script = os.path.join(here, "..", "python", "examples", "fleet_dask.py")
    with tempfile.TemporaryDirectory() as tmp:
        root = os.path.join(tmp, "fleet")
        n = make_fleet(root, data, copies)
        dirs = sorted(os.path.join(root, d) for d in os.listdir(root))
        check = wall([posecov_bin, "check", *dirs])
        report = wall([posecov_bin, "report", *dirs, "--json"])
        cli = check + report
        dask = wall([sys.executable, script, root, "--workers", str(workers), "--out", os.path.join(tmp, "f.jsonl")])
        start = wall([sys.executable, "-c",
                      "from distributed import Client, LocalCluster\n"
                      f"with LocalCluster(n_workers={workers}, threads_per_worker=1, dashboard_address=None) as c, Client(c): pass"])
    print(f"fleet logs={n} ({copies} robots x 5 logs) workers={workers} cores={os.cpu_count()}")
    print(f"  posecov check DIR...:          {check:.2f} s ({check / n * 1e3:.1f} ms/log)")
    print(f"  posecov report DIR... --json:  {report:.2f} s ({report / n * 1e3:.1f} ms/log)")
    print(f"  the CLI doing a task's work (report + check): {cli:.2f} s ({cli / n * 1e3:.1f} ms/log)")
    print(f"  fleet_dask.py on LocalCluster: {dask:.2f} s ({dask / n * 1e3:.1f} ms/log)")
    print(f"  LocalCluster start + stop alone: {start:.2f} s")
    print(f"  engine overhead (dask - cli): {dask - cli:.2f} s")


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    sub = p.add_subparsers(dest="what", required=True)
    c = sub.add_parser("compounding")
    c.add_argument("--steps", type=int, default=100)
    c.add_argument("--repeats", type=int, default=30)
    o = sub.add_parser("overhead")
    o.add_argument("--calls", type=int, default=200_000)
    f = sub.add_parser("fleet")
    f.add_argument("--posecov", required=True)
    f.add_argument("--data", required=True)
    f.add_argument("--copies", type=int, default=20)
    f.add_argument("--workers", type=int, default=2)
    a = p.parse_args()
    if a.what == "compounding":
        compounding(a.steps, a.repeats)
    elif a.what == "overhead":
        overhead(a.calls)
    else:
        fleet(a.posecov, a.data, a.copies, a.workers)


if __name__ == "__main__":
    main()
