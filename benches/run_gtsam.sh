#!/usr/bin/env bash
# Runs benches/gtsam_graphs.py (GTSAM's side of the pose-graph benchmark) in its own
# virtualenv with PyPI gtsam, one process per file (so each peak memory is its own).
# Usage: benches/run_gtsam.sh FILE.g2o...
# The virtualenv lives in ${POSECOV_GTSAM_VENV:-${XDG_CACHE_HOME:-$HOME/.cache}/posecov/gtsam-venv}.
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
venv="${POSECOV_GTSAM_VENV:-${XDG_CACHE_HOME:-$HOME/.cache}/posecov/gtsam-venv}"

# shellcheck source=benches/venv.sh
source "$here/venv.sh"
bench_venv "$venv" "gtsam, numpy" gtsam numpy
for file in "$@"; do
    env OMP_NUM_THREADS=1 "$venv/bin/python" "$here/gtsam_graphs.py" "$file"
done
