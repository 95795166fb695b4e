#!/usr/bin/env bash
# Peak memory of long propagations (BENCHMARKS.md §4): `posecov report` on an SE(2) odometry
# with `steps` = 10, 1000, 100000 at 2000 and 10^6 samples, peak RSS from GNU time.
# Particle memory must not grow with `steps` (statistics stream; at most 20 steps keep their
# particles and at most 1000 steps their numbers). Work beyond 10^10 particle-steps is
# refused up front, and that refusal is reported as such.
# Needs /usr/bin/time (`apt-get install time`). Usage: benches/memory_steps.sh [BIN]
set -euo pipefail
bin="${1:-${POSECOV_BIN:-target/release/posecov}}"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
printf '| samples | steps | peak RSS (MB) | wall (s) | result |\n|---:|---:|---:|---:|---|\n'
for samples in 2000 1000000; do
    for steps in 10 1000 100000; do
        f="$tmp/odometry_$steps.toml"
        cat > "$f" <<TOML
[scenario]
title = "long odometry"
group = "se2"
seed = 1
methods = ["first_order", "monte_carlo"]
[[pose]]
name = "world_from_robot"
mean = { xy_theta = [0.0, 0.0, 0.0] }
cov = { std = [0.01, 0.01, 0.01] }
[[operation]]
kind = "odometry"
input = "world_from_robot"
model = "increment"
controls = [[0.1, 0.0, 0.01]]
steps = $steps
noise = { std = [0.01, 0.01, 0.005] }
output = "robot"
TOML
        if /usr/bin/time -f "%M %e" -o "$tmp/time" "$bin" report "$f" --json --samples "$samples" > "$tmp/out.json" 2> "$tmp/err"; then
            result="ok ($(grep -c '"label"' "$tmp/out.json") results)"
        else
            result="refused: $(grep -o 'particle-steps.*' "$tmp/err" | head -c 90)"
        fi
        read -r kb secs < <(tail -1 "$tmp/time")
        printf '| %s | %s | %.0f | %s | %s |\n' "$samples" "$steps" "$(echo "$kb / 1024" | bc -l)" "$secs" "$result"
    done
done
