#!/usr/bin/env bash
# Soak benchmark (issue 14, deliverable 7; not a test): a run of 10^6 steps must hold its memory
# flat (resident set size near the start vs at the end within 5 %) and its throughput (summary
# particle_steps_per_second) within 10 % of a run of its first 10^4 steps.
# Usage: bench/soak.sh [path/to/loam]   (default build/loam; run with nothing else busy)
set -euo pipefail
cd "$(dirname "$0")/.."
LOAM=${1:-build/loam}
OUT=$(mktemp -d)
trap 'rm -rf "$OUT"' EXIT
# The 1D vibrating bar: about 0.0099 s per step, so 10^6 steps are t = 9 901 s; frames and
# history sparse so that the output does not dominate.
"$LOAM" run configs/vibrating_bar.yaml --threads 1 --out "$OUT/run" \
  --set time.end=9901 --set output.every_time=990 --set output.history_every=10000 \
  --set 'probes=[]' >"$OUT/log" 2>&1 &
pid=$!
rss=()
while kill -0 "$pid" 2>/dev/null; do
  r=$(awk '/VmRSS/ {print $2}' "/proc/$pid/status" 2>/dev/null || true)
  [ -n "$r" ] && rss+=("$r")
  sleep 1
done
wait "$pid"
"$LOAM" run configs/vibrating_bar.yaml --threads 1 --out "$OUT/short" --quiet \
  --set time.end=99.01 --set output.every_time=9.9 --set output.history_every=10000 \
  --set 'probes=[]'
short=$(python3 -c "import json; print(json.load(open('$OUT/short/summary.json'))['particle_steps_per_second'])")
long=$(python3 -c "import json; print(json.load(open('$OUT/run/summary.json'))['particle_steps_per_second'])")
steps=$(python3 -c "import json; print(json.load(open('$OUT/run/summary.json'))['steps'])")
python3 - "$short" "$long" "$steps" "${rss[@]}" <<'PY'
import sys
short, long, steps = float(sys.argv[1]), float(sys.argv[2]), int(sys.argv[3])
rss = [int(x) for x in sys.argv[4:]]
print(f"steps: {steps}")
print(f"particle-steps/s: {long:.4g} over 10^6 steps, {short:.4g} over the first 10^4 "
      f"({100 * (long / short - 1):+.1f} %; limit 10 %)")
if len(rss) >= 3:
    start, end = rss[1], rss[-1]  # the first sample may precede the set-up
    print(f"RSS: {start} kB near the start, {end} kB at the end ({100 * (end / start - 1):+.1f} %; limit 5 %)")
PY
