#!/usr/bin/env python3
"""Tables of ratios from criterion's estimates (BENCHMARKS.md).

Usage: benches/criterion_table.py lie [BASELINE]     (default BASELINE: new)
       benches/criterion_table.py sampling [BASELINE]
       benches/criterion_table.py raw PREFIX [BASELINE]

Reads target/criterion/<group>/<bench>/<BASELINE>/estimates.json (median point estimates).
lie: per op, posecov ns/op and peer_time / posecov_time (>= 1.0 means posecov is as fast).
"""
import json
import os
import sys

ROOT = os.environ.get("CRITERION_DIR", os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "target", "criterion"))
BATCH = 1024


def median_ns(group, bench, baseline):
    path = os.path.join(ROOT, group, bench, baseline, "estimates.json")
    with open(path) as f:
        return json.load(f)["median"]["point_estimate"]


def benches_of(group):
    out = []
    base = os.path.join(ROOT, group)
    for dirpath, dirnames, filenames in os.walk(base):
        if "benchmark.json" in filenames and os.path.basename(dirpath) in ("new", "base") or False:
            pass
    for name in sorted(os.listdir(base)):
        if name == "report":
            continue
        sub = os.path.join(base, name)
        if os.path.isdir(sub):
            # nested ids such as posecov_fill_par/1t/1000 become nested folders
            for dirpath, dirnames, filenames in os.walk(sub):
                if "estimates.json" in filenames:
                    rel = os.path.relpath(os.path.dirname(dirpath), base)
                    out.append(rel)
    return sorted(set(out))


def lie(baseline):
    groups = sorted(g for g in os.listdir(ROOT) if g.split(".")[0] in ("so2", "so3", "se2", "se3"))
    order = {"so2": 0, "so3": 1, "se2": 2, "se3": 3}
    ops = ["exp", "log", "compose", "inverse", "act", "adj", "jr", "jr_inv"]
    groups.sort(key=lambda g: (order[g.split(".")[0]], ops.index(g.split(".")[1])))
    print("| group | op | posecov ns/op | sophus_lie ns/op | ratio vs sophus_lie | nalgebra peer | nalgebra ns/op | ratio vs nalgebra |")
    print("|---|---|---:|---:|---:|---|---:|---:|")
    for g in groups:
        group, op = g.split(".")
        try:
            ours = median_ns(g, "posecov", baseline) / BATCH
        except FileNotFoundError:
            continue
        try:
            sophus = median_ns(g, "sophus_lie", baseline) / BATCH
            s = f"{sophus:.2f} | {sophus / ours:.2f}×"
        except FileNotFoundError:
            s = "– | –"
        peers = [b for b in os.listdir(os.path.join(ROOT, g)) if b.startswith("nalgebra")]
        rows = []
        for p in sorted(peers):
            try:
                t = median_ns(g, p, baseline) / BATCH
                rows.append(f"{p.removeprefix('nalgebra_')} | {t:.2f} | {t / ours:.2f}×")
            except FileNotFoundError:
                pass
        if not rows:
            rows = ["– | – | –"]
        for i, r in enumerate(rows):
            head = f"| {group.upper().replace('SO', 'SO(').replace('SE', 'SE(')}) | {op} | {ours:.2f} | {s} |" if i == 0 else "| | | | | |"
            print(f"{head} {r} |")


def sampling(baseline):
    for group in ("sampling.se2", "sampling.se3"):
        base = os.path.join(ROOT, group)
        if not os.path.isdir(base):
            continue
        print(f"\n{group}")
        print("| n | fill 1t ns/sample | floor 1t ns/sample | fill/floor 1t | fill 2t ns/sample | floor 2t ns/sample | fill/floor 2t | speed-up 1→2t | draw_par 2t ns/sample |")
        print("|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
        sizes = sorted({int(n) for n in os.listdir(os.path.join(base, "posecov_fill_par_1t"))} ) if os.path.isdir(os.path.join(base, "posecov_fill_par_1t")) else []
        for n in sizes:
            def t(name):
                try:
                    return median_ns(group, os.path.join(name, str(n)), baseline) / n
                except FileNotFoundError:
                    return float("nan")
            f1, z1 = t("posecov_fill_par_1t"), t("floor_normals_1t")
            f2, z2 = t("posecov_fill_par_2t"), t("floor_normals_2t")
            d2 = t("posecov_draw_par_2t")
            print(f"| {n:.0e} | {f1:.1f} | {z1:.1f} | {f1 / z1:.2f}× | {f2:.1f} | {z2:.1f} | {f2 / z2:.2f}× | {f1 / f2:.2f}× | {d2:.1f} |")


def raw(prefix, baseline):
    for g in sorted(os.listdir(ROOT)):
        if not g.startswith(prefix):
            continue
        for b in benches_of(g):
            try:
                print(f"{g}/{b}: {median_ns(g, b, baseline) / 1e6:.3f} ms")
            except FileNotFoundError:
                pass


if __name__ == "__main__":
    what = sys.argv[1] if len(sys.argv) > 1 else "lie"
    if what == "raw":
        raw(sys.argv[2], sys.argv[3] if len(sys.argv) > 3 else "new")
    else:
        bl = sys.argv[2] if len(sys.argv) > 2 else "new"
        {"lie": lie, "sampling": sampling}[what](bl)
