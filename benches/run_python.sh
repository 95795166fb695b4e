#!/usr/bin/env bash
# The Python package's benchmarks (issue 34, BENCHMARKS.md §11), side by side in one run:
#   1. Barfoot's compounding workload through the package vs pytransform3d's
#      concat_globally_uncertain_transforms (benches/python_bench.py compounding);
#   2. the call overhead of one compose with covariance from Python (python_bench.py overhead)
#      against the same calls in Rust (criterion, benches/compose.rs);
#   3. the fleet: generated logs through python/examples/fleet_dask.py on a LocalCluster vs
#      `posecov check DIR...` (python_bench.py fleet).
# 1 and 2 use a release wheel (`maturin build --release`, the build `pip install .` makes) in the
# bench's own virtualenv (pytransform3d lives there, never in CI's); 3 compares the wheel and the
# CLI built the same way: CI's dev-profile wheel ($HOME/.cache/posecov/python, made by
# .ci/python-venv) and CI's dev-profile binary ($CARGO_TARGET_DIR/debug/posecov).
# Usage: benches/run_python.sh [--copies 20]
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
root="$(dirname "$here")"
export CARGO_TARGET_DIR="${CARGO_TARGET_DIR:-$HOME/.cache/posecov/target}"
venv="${POSECOV_PYBENCH_VENV:-$HOME/.cache/posecov/bench-python}"
ci_venv="${POSECOV_PYTHON_VENV:-$HOME/.cache/posecov/python}"
copies=20
[ "${1:-}" = --copies ] && copies="$2"

# shellcheck source=benches/venv.sh
source "$here/venv.sh"
bench_venv "$venv" "pytransform3d, distributed, maturin, numpy" -r "$root/python/requirements-ci.txt"

cd "$root"
wheels="$(mktemp -d)"
trap 'rm -rf "$wheels"' EXIT
export PYO3_PYTHON="$venv/bin/python"
"$venv/bin/maturin" build --locked --release --interpreter "$venv/bin/python" --out "$wheels" >&2
"$venv/bin/python" -m pip install -q --no-input --force-reinstall --no-deps "$wheels"/posecov-*.whl

echo "== $(date -u +%H:%M) UTC, load $(cut -d' ' -f1-3 /proc/loadavg), $(nproc) cores"
(cd /tmp && "$venv/bin/python" "$here/python_bench.py" compounding)
(cd /tmp && "$venv/bin/python" "$here/python_bench.py" overhead)
cargo bench --no-default-features --bench compose -- --warm-up-time 1 --measurement-time 3 2>&1 |
    grep -E '^compose/|time:'

bin="${POSECOV:-$CARGO_TARGET_DIR/debug/posecov}"
[ -x "$bin" ] || { echo "no posecov binary at $bin (cargo test builds it)" >&2; exit 1; }
[ -x "$ci_venv/bin/python" ] || { echo "no CI virtualenv at $ci_venv (.ci/python-venv makes it)" >&2; exit 1; }
(cd /tmp && "$ci_venv/bin/python" "$here/python_bench.py" fleet --posecov "$bin" \
    --data "$root/tests/data" --copies "$copies" --workers 2)
