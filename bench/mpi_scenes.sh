#!/usr/bin/env bash
# The shipped scenes on 2 ranks against the serial run (bench/RESULTS.md "Shipped scenes on
# ranks"): each CONFIG (with optional --set overrides after a '|') runs at 1 rank x 2 threads and
# at 2 ranks x 1 thread; bench/mpi_scenes_compare.py prints speed, steps, the stage records and
# the verify metrics side by side. Run it on an otherwise idle machine:
#   bash bench/mpi_scenes.sh 'configs/seed004_slope_staged.yaml' 'configs/x.yaml|--set time.end=1'
set -euo pipefail
cd "$(dirname "$0")/.."
LOAM=build/loam
OUT=${OUT:-$(mktemp -d)}
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
export OMPI_MCA_btl_vader_single_copy_mechanism=none OMP_WAIT_POLICY=passive
for spec in "$@"; do
  cfg=${spec%%|*}
  sets=""
  [[ "$spec" == *"|"* ]] && sets=${spec#*|}
  name=$(basename "$cfg" .yaml)
  # shellcheck disable=SC2086
  $LOAM run "$cfg" $sets --quiet --threads 2 --overwrite --out "$OUT/$name.serial"
  # shellcheck disable=SC2086
  mpirun -np 2 --bind-to none $LOAM run "$cfg" $sets --quiet --threads 1 --overwrite \
    --out "$OUT/$name.np2"
  /usr/bin/python3 bench/mpi_scenes_compare.py "$OUT/$name.serial" "$OUT/$name.np2"
done
echo "results in $OUT"
