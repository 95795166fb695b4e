#!/usr/bin/env bash
# Runs benches/na568_numpy.py (the NumPy/SciPy twin of benches/na568.rs) in its own virtualenv.
# Usage: benches/run_numpy.sh [--particles 1000] [--repeats 3] [--seed 568]
# The virtualenv lives in ${POSECOV_BENCH_VENV:-${XDG_CACHE_HOME:-$HOME/.cache}/posecov/bench-venv}.
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
venv="${POSECOV_BENCH_VENV:-${XDG_CACHE_HOME:-$HOME/.cache}/posecov/bench-venv}"

# shellcheck source=benches/venv.sh
source "$here/venv.sh"
bench_venv "$venv" "numpy, scipy" numpy scipy

# Some machines pin OpenBLAS to an old kernel through these variables; they slow a current
# NumPy. Unset them for this benchmark only (3x3 matrices barely touch BLAS either way).
env -u OPENBLAS_CORETYPE -u OPENBLAS_L2_SIZE OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 \
    "$venv/bin/python" "$here/na568_numpy.py" "$@"
