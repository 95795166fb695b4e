#!/usr/bin/env bash
# posecov beside GTSAM on pose graphs, interleaved: for each file, REPEATS rounds of
# examples/graph_bench (release, no Rerun) under /usr/bin/time, then GTSAM's side
# (benches/run_gtsam.sh), so both see the same load. Same reading (GTSAM's readG2o), same
# initial guess, same anchor and stop criteria (BENCHMARKS.md §7). One JSON line per run,
# prefixed by its side; posecov's line gets its peak RSS from /usr/bin/time.
# Usage: benches/run_graphs.sh [--repeats N] FILE.g2o...
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
root="$(dirname "$here")"
repeats=1
if [ "${1:-}" = "--repeats" ]; then
    repeats="$2"
    shift 2
fi
(cd "$root" && cargo build --quiet --release --no-default-features --example graph_bench)
bench="${CARGO_TARGET_DIR:-$root/target}/release/examples/graph_bench"
rss="$(mktemp)"
trap 'rm -f "$rss"' EXIT

for file in "$@"; do
    for _ in $(seq "$repeats"); do
        line="$(/usr/bin/time -f '%M' -o "$rss" "$bench" "$file" gtsam)"
        echo "posecov ${line%\}}, \"peak_rss_kb\": $(tail -n 1 "$rss")}"
        "$here/run_gtsam.sh" "$file" | sed 's/^/gtsam   /'
    done
done
