"""GTSAM's side of the pose-graph benchmark (BENCHMARKS.md, "Pose graphs beside GTSAM").

For each g2o file: read it as GTSAM's readG2o does, hold the first vertex with a prior of
σ = 1e-6 on every axis (posecov holds it exactly), optimise with Levenberg-Marquardt under
GTSAM's default stop criteria (relative and absolute decrease 1e-5 of the error, 100
iterations, lambda from 1e-5, x10 / /10, bound 1e5 - posecov uses the same), then ask
Marginals for every pose's marginal covariance one at a time, as GTSAM's API has it. Prints
one JSON line per file: seconds to optimise, seconds for every marginal, iterations, errors.
Files without vertex lines (manhattan, CSAIL) get the initial guess posecov chains (odometry
edges first, then the others), built here the same way.

Usage: benches/run_gtsam.sh FILE...
"""
import json
import resource
import sys
import time

import gtsam
import numpy as np


def chained_initial(graph, is3d):
    between = []
    for k in range(graph.size()):
        f = graph.at(k)
        if f is None or len(f.keys()) != 2:
            continue
        between.append((f.keys()[0], f.keys()[1], f.measured()))
    ids = sorted({i for e in between for i in e[:2]})
    order = [e for e in between if abs(e[0] - e[1]) == 1] + [e for e in between if abs(e[0] - e[1]) != 1]
    identity = gtsam.Pose3() if is3d else gtsam.Pose2()
    placed = {}
    while True:
        changed = True
        while changed:
            changed = False
            for i, j, z in order:
                if i in placed and j not in placed:
                    placed[j] = placed[i].compose(z)
                    changed = True
                elif j in placed and i not in placed:
                    placed[i] = placed[j].compose(z.inverse())
                    changed = True
        rest = [i for i in ids if i not in placed]
        if not rest:
            break
        placed[rest[0]] = identity
    values = gtsam.Values()
    for i, x in placed.items():
        values.insert(i, x)
    return values


def run(path):
    is3d = "VERTEX_SE3" in open(path).read(4096) or "EDGE_SE3" in open(path).read(4096)
    graph, initial = gtsam.readG2o(path, is3d)
    if initial.size() == 0:
        initial = chained_initial(graph, is3d)
    first = min(initial.keys())
    if is3d:
        noise = gtsam.noiseModel.Isotropic.Sigma(6, 1e-6)
        graph.add(gtsam.PriorFactorPose3(first, initial.atPose3(first), noise))
    else:
        noise = gtsam.noiseModel.Isotropic.Sigma(3, 1e-6)
        graph.add(gtsam.PriorFactorPose2(first, initial.atPose2(first), noise))
    params = gtsam.LevenbergMarquardtParams()
    params.setRelativeErrorTol(1e-5)
    params.setAbsoluteErrorTol(1e-5)
    params.setMaxIterations(100)
    error_before = graph.error(initial)
    t0 = time.perf_counter()
    optimizer = gtsam.LevenbergMarquardtOptimizer(graph, initial, params)
    result = optimizer.optimize()
    t1 = time.perf_counter()
    marginals = gtsam.Marginals(graph, result)
    t2 = time.perf_counter()
    for key in result.keys():
        if key != first:
            marginals.marginalCovariance(key)
    t3 = time.perf_counter()
    print(json.dumps({
        "file": path.split("/")[-1],
        "poses": int(result.size()),
        "optimize_s": round(t1 - t0, 4),
        "marginals_s": round(t3 - t1, 4),
        "marginals_construct_s": round(t2 - t1, 4),
        "marginal_queries_s": round(t3 - t2, 4),
        "iterations": optimizer.iterations(),
        "chi2_before": 2 * error_before,
        "chi2_after": 2 * graph.error(result),
        "peak_rss_kb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss,
    }), flush=True)


for p in sys.argv[1:]:
    run(p)
