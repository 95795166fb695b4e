#!/usr/bin/env bash
# posecov's bag reader vs the Python `rosbags` package on the same bags, side by side in one
# run: robot_localization's test2.bag as shipped (bz2) and rewritten ten times over (30 600
# Odometry messages) with no, lz4 and bz2 chunk compression; the criterion bench
# benches/bag_read.rs, then benches/bag_rosbags.py in its own virtualenv, then the ratios of
# messages per second.
# Usage: benches/run_rosbags.sh [--repeats 5]
# The virtualenv lives in ${POSECOV_ROSBAGS_VENV:-${XDG_CACHE_HOME:-$HOME/.cache}/posecov/rosbags-venv}.
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
root="$(dirname "$here")"
venv="${POSECOV_ROSBAGS_VENV:-${XDG_CACHE_HOME:-$HOME/.cache}/posecov/rosbags-venv}"
bag="$root/tests/data/robot_localization/test2.bag"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT

# shellcheck source=benches/venv.sh
source "$here/venv.sh"
bench_venv "$venv" "rosbags" 'rosbags==0.11.9'

bags=()
for c in none lz4 bz2; do
    "$venv/bin/python" "$here/bag_rosbags.py" "$bag" --rewrite "$work/jackal10_$c.bag" --compression "$c" --copies 10
    bags+=("$work/jackal10_$c.bag")
done

cd "$root"
out="$(POSECOV_BENCH_BAGS="$(IFS=:; echo "${bags[*]}")" \
    cargo bench --no-default-features --bench bag_read -- --warm-up-time 1 --measurement-time 3 2>&1)"
rate() { # criterion's median throughput of bench $1, in messages/s
    echo "$out" | grep -A3 "bag_read/$1 " | grep "thrpt:" | head -1 |
        sed -E 's/.*thrpt: *\[[^ ]+ [^ ]+ ([0-9.]+) ([KM]?)elem\/s.*/\1 \2/' |
        awk '{ m = ($2 == "K") ? 1e3 : (($2 == "M") ? 1e6 : 1); printf "%.0f", $1 * m }'
}
printf "%-16s %14s %14s %8s\n" "bag" "posecov msg/s" "rosbags msg/s" "ratio"
for name in test2 jackal10_none jackal10_lz4 jackal10_bz2; do
    if [ "$name" = test2 ]; then file="$bag"; bench=ros1_test2_bz2; else file="$work/$name.bag"; bench="$name"; fi
    p="$(rate "$bench")"
    r="$("$venv/bin/python" "$here/bag_rosbags.py" "$file" "$@" | sed -E 's/.*: ([0-9,]+) messages\/s/\1/' | tr -d ,)"
    printf "%-16s %14s %14s %7.1fx\n" "$name" "$p" "$r" "$(python3 -c "print($p / $r)")"
done
