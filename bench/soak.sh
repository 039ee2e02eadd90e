#!/usr/bin/env bash
# Soak benchmark (not a test): a run of 10^6 steps must hold its memory
# flat (resident set size near the start vs at the end within 5 %) and its throughput (summary
# particle_steps_per_second) within 10 % of a run of its first 10^4 steps.
# Usage: bench/soak.sh [path/to/loam]   (default build/loam; run with nothing else busy)
set -euo pipefail
cd "$(dirname "$0")/.."
LOAM=${1:-build/loam}
OUT=$(mktemp -d)
trap 'rm -rf "$OUT"' EXIT
# The 1D vibrating bar on 0.05 m cells (1000 points): 4.95e-4 s per step, so 10^6 steps are
# t = 495 s (about 100 s of wall time), long enough for the progress lines (every 3 s) to show
# a trend and for the set-up to be negligible in a run of 10^4 steps; frames and history
# sparse so that the output does not dominate.
BAR=(configs/vibrating_bar.yaml --threads 1 --set grid.cell_size=0.05
  --set output.history_every=10000 --set 'probes=[]')
"$LOAM" run "${BAR[@]}" --out "$OUT/run" --set time.end=495.05 \
  --set output.every_time=49.5 >"$OUT/log" 2>&1 &
pid=$!
rss=()
while kill -0 "$pid" 2>/dev/null; do
  r=$(awk '/VmRSS/ {print $2}' "/proc/$pid/status" 2>/dev/null || true)
  [ -n "$r" ] && rss+=("$r")
  sleep 1
done
wait "$pid"
"$LOAM" run "${BAR[@]}" --out "$OUT/short" --quiet --set time.end=4.9505 \
  --set output.every_time=0.495
short=$(python3 -c "import json; print(json.load(open('$OUT/short/summary.json'))['particle_steps_per_second'])")
long=$(python3 -c "import json; print(json.load(open('$OUT/run/summary.json'))['particle_steps_per_second'])")
steps=$(python3 -c "import json; print(json.load(open('$OUT/run/summary.json'))['steps'])")
python3 - "$short" "$long" "$steps" "$OUT/log" "${rss[@]}" <<'PY'
import re, statistics, sys
short, long, steps = float(sys.argv[1]), float(sys.argv[2]), int(sys.argv[3])
rss = [int(x) for x in sys.argv[5:]]
print(f"steps: {steps}")
print(f"particle-steps/s: {long:.4g} over 10^6 steps, {short:.4g} over the first 10^4 "
      f"({100 * (long / short - 1):+.1f} %; limit 10 %)")
# The progress lines' steps/s over each 3 s interval of the long run: the median of its first
# three intervals against its last three (a slow-down within the run, not the host's drift
# between two runs).
rates = [float(m.group(1)) for m in
         re.finditer(r"step \d+\s+([0-9.e+]+) steps/s", open(sys.argv[4]).read())]
if len(rates) >= 6:
    first, last = statistics.median(rates[:3]), statistics.median(rates[-3:])
    print(f"steps/s within the run: {first:.4g} in its first three 3-s intervals, {last:.4g} in "
          f"its last three ({100 * (last / first - 1):+.1f} %)")
if len(rss) >= 3:
    start, end = rss[1], rss[-1]  # the first sample may precede the set-up
    print(f"RSS: {start} kB near the start, {end} kB at the end ({100 * (end / start - 1):+.1f} %; limit 5 %)")
    # A one-time step (the first frame after t = 0 allocates the HDF5 library's buffers) is not
    # a leak: the growth over the run's last 90 % shows one.
    tenth = rss[len(rss) // 10]
    print(f"RSS over the last 90 % of the run: {tenth} -> {end} kB ({100 * (end / tenth - 1):+.2f} %)")
PY
