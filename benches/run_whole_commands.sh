#!/usr/bin/env bash
# Issue 33 item 5: posecov's whole commands beside GTSAM's whole Python process, side by side
# in one run, each timed from outside with /usr/bin/time (wall seconds, user seconds, peak RSS).
# For each file: `posecov report F --json`, `posecov F --save x.rrd`, `posecov figure F -o x.svg`,
# then GTSAM's script (benches/gtsam_graphs.py: readG2o, a prior, LM, Marginals and every
# marginalCovariance) in its own virtualenv (benches/venv.sh, as benches/run_gtsam.sh makes it).
# One line per command: file, command, wall s, user s, peak KB (and the .rrd's bytes for --save).
# Usage: benches/run_whole_commands.sh POSECOV_BINARY FILE.g2o...
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
venv="${POSECOV_GTSAM_VENV:-${XDG_CACHE_HOME:-$HOME/.cache}/posecov/gtsam-venv}"
# shellcheck source=benches/venv.sh
source "$here/venv.sh"
bench_venv "$venv" "gtsam, numpy" gtsam numpy
bin="$1"
shift
out="$(mktemp -d)"
trap 'rm -rf "$out"' EXIT

timed() {
    local name="$1" label="$2"
    shift 2
    /usr/bin/time -f "%e %U %M" -o "$out/time" "$@" >/dev/null 2>"$out/err" || {
        echo "$name $label FAILED: $(tail -n 2 "$out/err")"
        return
    }
    read -r wall user kb <"$out/time"
    echo "$name $label wall_s=$wall user_s=$user peak_kb=$kb ${extra:-}"
}

for file in "$@"; do
    name="$(basename "$file" .g2o)"
    extra="" timed "$name" report "$bin" report "$file" --json
    rm -f "$out/x.rrd"
    timed "$name" save "$bin" "$file" --save "$out/x.rrd" 2>/dev/null || true
    echo "$name rrd_bytes=$(stat -c %s "$out/x.rrd" 2>/dev/null || echo 0)"
    extra="" timed "$name" figure "$bin" figure "$file" -o "$out/x.svg"
    extra="" timed "$name" gtsam env OMP_NUM_THREADS=1 "$venv/bin/python" "$here/gtsam_graphs.py" "$file"
done
