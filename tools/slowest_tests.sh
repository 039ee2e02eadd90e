#!/usr/bin/env bash
# Prints the slowest tests of the last ctest run in a build directory (from CTest's own log),
# with the host's cores, CPU quota and load: .ci/run ends with it, so a CI log that is cut in
# the middle still shows where the time of the test tier went.
#   tools/slowest_tests.sh [BUILD_DIR] [N]
set -uo pipefail
BUILD_DIR=${1:-build}
N=${2:-25}
LOG="$BUILD_DIR/Testing/Temporary/LastTest.log"
quota=$(cat /sys/fs/cgroup/cpu.max 2>/dev/null ||
        cat /sys/fs/cgroup/cpu/cpu.cfs_quota_us 2>/dev/null || echo "none found")
echo "host: nproc $(nproc), CPU quota: $quota, load average: $(cut -d' ' -f1-3 /proc/loadavg)"
if [ ! -f "$LOG" ]; then
  echo "no ctest log at $LOG"
  exit 0
fi
echo "slowest tests of the last ctest run:"
awk '/^[0-9]+\/[0-9]+ Test: / { sub(/^[0-9]+\/[0-9]+ Test: /, ""); name = $0 }
     /^Test time = / { printf "%8.2f s  %s\n", $4, name }' "$LOG" | sort -rn | head -n "$N"
awk '/^Test time = / { t += $4; n++ }
     END { printf "%8.2f s  in all over %d tests (summed; ctest -j 2 runs two at a time)\n", t, n }' "$LOG"
