#!/usr/bin/env bash
# posecov's bag reader vs the Python `rosbags` package on the same bags, side by side in one
# run: robot_localization's test2.bag as shipped (bz2) and rewritten ten times over (30 600
# Odometry messages) with no, lz4 and bz2 chunk compression, and ten times over with a new
# pose covariance in every message, as an EKF publishes it (`--ekf`: the bags as shipped
# publish one covariance throughout), uncompressed and lz4; the criterion bench
# benches/bag_read.rs, then benches/bag_rosbags.py in its own virtualenv, then the ratios of
# messages per second. Then, from the same criterion run: posecov's read of each bz2 bag
# against libbz2 alone decompressing its chunks on the same threads (bag_libbz2/*; the rule:
# ≤ 1.2×), and the share of the health classes and σ statistics in each read (bag_health/*;
# the rule: they add ≤ 10 % to the rest of the read). With POSECOV_BIN set (a posecov binary), the peak RSS of
# `posecov report BAG --json` on the bag ten and a hundred times over (memory must not grow
# with the log's length; needs /usr/bin/time).
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
for c in none lz4; do
    "$venv/bin/python" "$here/bag_rosbags.py" "$bag" --rewrite "$work/ekf10_$c.bag" --compression "$c" --copies 10 --ekf
    bags+=("$work/ekf10_$c.bag")
done
if [ -n "${POSECOV_BIN:-}" ]; then
    "$venv/bin/python" "$here/bag_rosbags.py" "$bag" --rewrite "$work/jackal100_bz2.bag" --compression bz2 --copies 100
fi

cd "$root"
# One bag at a time, posecov's three measures (criterion) then rosbags on the same bag: what is
# compared is measured within a minute, whatever else the machine is doing.
cargo bench --no-default-features --bench bag_read --no-run >/dev/null 2>&1
out=""
declare -A rosbags
for name in test2 jackal10_none jackal10_lz4 jackal10_bz2 ekf10_none ekf10_lz4; do
    if [ "$name" = test2 ]; then file="$bag"; bench=ros1_test2_bz2; else file="$work/$name.bag"; bench="$name"; fi
    out+="$(POSECOV_BENCH_BAGS="$(IFS=:; echo "${bags[*]}")" \
        cargo bench --no-default-features --bench bag_read -- --warm-up-time 1 --measurement-time 3 "/$bench\$" 2>&1)"$'\n'
    rosbags[$name]="$("$venv/bin/python" "$here/bag_rosbags.py" "$file" "$@" | sed -E 's/.*: ([0-9,]+) messages\/s/\1/' | tr -d ,)"
done
rate() { # criterion's median throughput of bench $1 (group/name), in messages/s
    # (a long name is on a line of its own, a short one padded before its numbers)
    echo "$out" | grep -A3 -E "^$1( |\$)" | grep "thrpt:" | head -1 |
        sed -E 's/.*thrpt: *\[[^ ]+ [^ ]+ ([0-9.]+) ([KM]?)elem\/s.*/\1 \2/' |
        awk '{ m = ($2 == "K") ? 1e3 : (($2 == "M") ? 1e6 : 1); printf "%.0f", $1 * m }'
}
printf "%-16s %14s %14s %8s\n" "bag" "posecov msg/s" "rosbags msg/s" "ratio"
for name in test2 jackal10_none jackal10_lz4 jackal10_bz2 ekf10_none ekf10_lz4; do
    if [ "$name" = test2 ]; then bench=ros1_test2_bz2; else bench="$name"; fi
    p="$(rate "bag_read/$bench")"
    r="${rosbags[$name]}"
    printf "%-16s %14s %14s %7.1fx\n" "$name" "$p" "$r" "$(python3 -c "print($p / $r)")"
done

echo
printf "%-16s %14s %14s %10s\n" "bz2 bag" "posecov msg/s" "libbz2 msg/s" "time ratio"
for name in ros1_test2_bz2 jackal10_bz2; do
    p="$(rate "bag_read/$name")"
    z="$(rate "bag_libbz2/$name")"
    printf "%-16s %14s %14s %9.2fx\n" "$name" "$p" "$z" "$(python3 -c "print($z / $p)")"
done
echo
# share: health's time over the whole read's (which includes it); adds: over the rest of the
# read's, what health adds to it (the rule: ≤ 10 %).
printf "%-16s %14s %16s %8s %8s\n" "bag" "read msg/s" "health msg/s" "share" "adds"
for name in ros1_test2_bz2 jackal10_none jackal10_lz4 jackal10_bz2 ekf10_none ekf10_lz4; do
    p="$(rate "bag_read/$name")"
    h="$(rate "bag_health/$name")"
    printf "%-16s %14s %16s %7.1f%% %7.1f%%\n" "$name" "$p" "$h" "$(python3 -c "print(100 * $p / $h)")" \
        "$(python3 -c "print(100 * $p / ($h - $p))")"
done
if [ -n "${POSECOV_BIN:-}" ]; then
    echo
    printf "%-16s %10s %14s\n" "bag" "messages" "peak RSS (MB)"
    for copies in 10 100; do
        name="jackal${copies}_bz2"
        kb="$( { /usr/bin/time -f "%M" "$POSECOV_BIN" report "$work/$name.bag" --json >/dev/null; } 2>&1 | tail -1)"
        n=$((copies * 3060))
        printf "%-16s %10s %14.1f\n" "$name" "$n" "$(python3 -c "print($kb / 1024)")"
    done
fi
