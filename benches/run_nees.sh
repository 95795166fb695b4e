#!/usr/bin/env bash
# NEES over a one-hour log, posecov vs Python `rosbags` + NumPy, side by side in one run
# (BENCHMARKS.md §8): examples/nees_bench writes the log of tests/common/logs.rs with its truth
# spanning SECONDS (default 3600: /ground_truth and /tf at 100 Hz, /ekf and /ekf_overconfident
# at 10 Hz); then, REPEATS rounds of posecov's `report LOG --reference /ground_truth --json`
# (examples/nees_bench report: the library call the binary makes, release, no Rerun) and
# benches/nees_rosbags.py in its own virtualenv, interleaved so both see the same load; each
# process timed whole by /usr/bin/time (wall clock and CPU time, user + sys, start-up included:
# on a loaded machine the wall clock waits for a core, the CPU time less so). Checks that both
# give the same ANEES (1e-9 relative), then prints each round, the medians and their ratios.
# Usage: benches/run_nees.sh [--repeats 5] [--seconds 3600]
# The virtualenv lives in ${POSECOV_NEES_VENV:-${XDG_CACHE_HOME:-$HOME/.cache}/posecov/nees-venv}.
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
root="$(dirname "$here")"
venv="${POSECOV_NEES_VENV:-${XDG_CACHE_HOME:-$HOME/.cache}/posecov/nees-venv}"
repeats=5
seconds=3600
while [ $# -gt 0 ]; do
    case "$1" in
    --repeats) repeats="$2"; shift 2 ;;
    --seconds) seconds="$2"; shift 2 ;;
    *) echo "usage: $0 [--repeats N] [--seconds S]" >&2; exit 2 ;;
    esac
done
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT

# shellcheck source=benches/venv.sh
source "$here/venv.sh"
bench_venv "$venv" "rosbags, numpy" 'rosbags==0.11.9' numpy

(cd "$root" && cargo build --quiet --release --no-default-features --example nees_bench)
bench="${CARGO_TARGET_DIR:-$root/target}/release/examples/nees_bench"
log="$work/hour.mcap"
"$bench" write "$log" "$seconds"
echo "log: $(du -h "$log" | cut -f1), truth spanning $seconds s; $("$venv/bin/python" -c 'import numpy, rosbags, sys; print(f"Python {sys.version.split()[0]}, numpy {numpy.__version__}, rosbags", end=" ")'; "$venv/bin/python" -m pip show rosbags | sed -n 's/^Version: //p')"

timed() { # runs "$@" > $out; prints "WALL CPU" in seconds (CPU = user + sys)
    /usr/bin/time -f '%e %U %S' -o "$work/time" "$@" >"$out"
    awk '{ printf "%.2f %.2f", $1, $2 + $3 }' "$work/time"
}

printf "%-6s %22s %22s %16s %s\n" round "posecov wall / CPU s" "rosbags wall / CPU s" "ratio wall / CPU" "load (1-min) before each"
p_times=()
r_times=()
for round in $(seq "$repeats"); do
    load_p="$(cut -d' ' -f1 /proc/loadavg)"
    out="$work/posecov.jsonl"; p="$(timed "$bench" report "$log")"
    load_r="$(cut -d' ' -f1 /proc/loadavg)"
    out="$work/rosbags.jsonl"; r="$(timed "$venv/bin/python" "$here/nees_rosbags.py" "$log")"
    p_times+=("${p/ /,}")
    r_times+=("${r/ /,}")
    read -r pw pc <<<"$p"
    read -r rw rc <<<"$r"
    printf "%-6s %22s %22s %16s %s\n" "$round" "$pw / $pc" "$rw / $rc" \
        "$(python3 -c "print(f'{$rw / $pw:.1f}x / {$rc / $pc:.1f}x')")" "$load_p / $load_r"
done

python3 - "$work/posecov.jsonl" "$work/rosbags.jsonl" "${p_times[*]}" "${r_times[*]}" <<'EOF'
import json, statistics, sys
p = {j["topic"]: j for j in map(json.loads, open(sys.argv[1]))}
r = {j["topic"]: j for j in map(json.loads, open(sys.argv[2]))}
assert p.keys() == r.keys(), (p.keys(), r.keys())
worst = 0.0
for topic in sorted(p):
    a, b = p[topic], r[topic]
    assert a["messages"] == b["messages"], (topic, a["messages"], b["messages"])
    assert abs(a["inside_95"] - b["inside_95"]) < 1e-12, (topic, a["inside_95"], b["inside_95"])
    for key in ("anees", "anees_position", "anees_orientation"):
        rel = abs(a[key] - b[key]) / abs(b[key])
        worst = max(worst, rel)
        assert rel < 1e-9, (topic, key, a[key], b[key])
    print(f"{topic}: {a['messages']} messages, ANEES {a['anees']:.12g} (posecov) {b['anees']:.12g} (rosbags), "
          f"position {a['anees_position']:.6g}, orientation {a['anees_orientation']:.6g}, inside_95 {a['inside_95']:.4f}")
print(f"same ANEES on both sides: largest relative difference {worst:.1e}")
def medians(arg):
    runs = [tuple(map(float, r.split(","))) for r in arg.split()]
    return statistics.median(r[0] for r in runs), statistics.median(r[1] for r in runs)
(pw, pc), (rw, rc) = medians(sys.argv[3]), medians(sys.argv[4])
print(f"median wall: posecov {pw:.2f} s, rosbags + NumPy {rw:.2f} s, ratio {rw / pw:.1f}x")
print(f"median CPU:  posecov {pc:.2f} s, rosbags + NumPy {rc:.2f} s, ratio {rc / pc:.1f}x")
EOF
