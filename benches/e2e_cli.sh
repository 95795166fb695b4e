#!/usr/bin/env bash
# End-to-end CLI timings for every bundled scenario (BENCHMARKS.md):
#   posecov report <scenario> --json      and      posecov <scenario> --save x.rrd
# Needs the release binary (`cargo build --release`) and hyperfine (`apt-get install hyperfine`).
# Usage: benches/e2e_cli.sh [OUT_DIR]   (writes OUT_DIR/report.json and OUT_DIR/save.json)
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
bin="${POSECOV_BIN:-$here/../target/release/posecov}"
out="${1:-$here/../target/e2e}"
mkdir -p "$out"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
mapfile -t names < <("$bin" list | awk '{print $1}')
report=(); save=()
for n in "${names[@]}"; do
    report+=(-n "report $n" "$bin report $n --json > /dev/null")
    save+=(-n "save $n" "$bin $n --save $tmp/$n.rrd > /dev/null")
done
hyperfine --warmup 1 --runs "${RUNS:-5}" --export-json "$out/report.json" --export-markdown "$out/report.md" "${report[@]}"
hyperfine --warmup 1 --runs "${RUNS:-5}" --export-json "$out/save.json" --export-markdown "$out/save.md" "${save[@]}"
ls -l "$tmp"/*.rrd | awk '{print $5, $9}' > "$out/rrd_sizes.txt"
