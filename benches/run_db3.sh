#!/usr/bin/env bash
# posecov's ROS 2 SQLite bag reader vs the Python `rosbags` package on the same bags, side by
# side in one run (issue 32): tests/data/ros2/arc_v9 (100 Odometry + 25 PoseWithCovarianceStamped
# + 120 skipped messages) rewritten 200 times over by rosbags' own writer (25 000 pose messages
# of 49 000, stamps shifted), with no compression, zstd per message and zstd per file; the
# criterion bench benches/bag_read.rs (`bag_read/NAME`), then benches/db3_rosbags.py in its own
# virtualenv on the same bag, then the ratio of pose messages per second (the rule: ≥ 10×).
# Usage: benches/run_db3.sh [--repeats 5]
# The virtualenv lives in ${POSECOV_ROSBAGS_VENV:-${XDG_CACHE_HOME:-$HOME/.cache}/posecov/rosbags-venv}.
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
root="$(dirname "$here")"
venv="${POSECOV_ROSBAGS_VENV:-${XDG_CACHE_HOME:-$HOME/.cache}/posecov/rosbags-venv}"
src="$root/tests/data/ros2/arc_v9"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT

# shellcheck source=benches/venv.sh
source "$here/venv.sh"
bench_venv "$venv" "rosbags" 'rosbags==0.11.9'

names=()
bags=()
for c in none message file; do
    "$venv/bin/python" "$here/db3_rosbags.py" "$src" --rewrite "$work/db3_arc200_$c" --compression "$c" --copies 200
    names+=("db3_arc200_$c")
    bags+=("$work/db3_arc200_$c")
done

cd "$root"
cargo bench --no-default-features --bench bag_read --no-run >/dev/null 2>&1
out=""
declare -A rosbags
for name in "${names[@]}"; do
    out+="$(POSECOV_BENCH_BAGS="$(IFS=:; echo "${bags[*]}")" \
        cargo bench --no-default-features --bench bag_read -- --warm-up-time 1 --measurement-time 3 "/$name\$" 2>&1)"$'\n'
    rosbags[$name]="$("$venv/bin/python" "$here/db3_rosbags.py" "$work/$name" "$@" | sed -E 's/.*: ([0-9,]+) messages\/s/\1/' | tr -d ,)"
done
rate() { # criterion's median throughput of bench $1 (group/name), in messages/s
    echo "$out" | grep -A3 -E "^$1( |\$)" | grep "thrpt:" | head -1 |
        sed -E 's/.*thrpt: *\[[^ ]+ [^ ]+ ([0-9.]+) ([KM]?)elem\/s.*/\1 \2/' |
        awk '{ m = ($2 == "K") ? 1e3 : (($2 == "M") ? 1e6 : 1); printf "%.0f", $1 * m }'
}
printf "%-20s %14s %14s %8s\n" "bag" "posecov msg/s" "rosbags msg/s" "ratio"
for name in "${names[@]}"; do
    p="$(rate "bag_read/$name")"
    r="${rosbags[$name]}"
    printf "%-20s %14s %14s %7.1fx\n" "$name" "$p" "$r" "$(python3 -c "print($p / $r)")"
done
