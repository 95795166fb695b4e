#!/usr/bin/env bash
# Runs benches/na568_numpy.py (the NumPy/SciPy twin of benches/na568.rs) in its own virtualenv.
# Usage: benches/run_numpy.sh [--particles 1000] [--repeats 3] [--seed 568]
# The virtualenv lives in ${POSECOV_BENCH_VENV:-${XDG_CACHE_HOME:-$HOME/.cache}/posecov/bench-venv}.
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
venv="${POSECOV_BENCH_VENV:-${XDG_CACHE_HOME:-$HOME/.cache}/posecov/bench-venv}"

if [ ! -x "$venv/bin/python" ]; then
    mkdir -p "$(dirname "$venv")"
    python3 -m venv "$venv"
    "$venv/bin/python" -m pip install --quiet --upgrade pip
fi
if ! "$venv/bin/python" -c 'import numpy, scipy' 2>/dev/null; then
    "$venv/bin/python" -m pip install --quiet numpy scipy
fi

# Some machines pin OpenBLAS to an old kernel through these variables; they slow a current
# NumPy. Unset them for this benchmark only (3x3 matrices barely touch BLAS either way).
env -u OPENBLAS_CORETYPE -u OPENBLAS_L2_SIZE OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 \
    "$venv/bin/python" "$here/na568_numpy.py" "$@"
