#!/usr/bin/env bash
# Whole-run speed on ranks and threads (bench/RESULTS.md "MPI whole runs"): the bench blocks as
# run files, 1 rank x 1 thread, 2 ranks x 1 thread and 1 rank x 2 threads, interleaved in
# ROUNDS rounds (the host drifts); prints particle-steps/s of each run and the medians.
# Run it on an otherwise idle machine: [SCENES=mpi_block_2d] bash bench/mpi_speedup.sh [ROUNDS]
set -euo pipefail
cd "$(dirname "$0")/.."
ROUNDS=${1:-3}
LOAM=build/loam
OUT=$(mktemp -d)
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
export OMPI_MCA_btl_vader_single_copy_mechanism=none OMP_WAIT_POLICY=passive
rate() { grep -o '"particle_steps_per_second": [0-9.e+]*' "$1/summary.json" | awk '{print $2}'; }
for scene in ${SCENES:-mpi_block_2d mpi_block_3d}; do
  for round in $(seq "$ROUNDS"); do
    $LOAM run bench/$scene.yaml --quiet --threads 1 --overwrite --out "$OUT/a"
    mpirun -np 2 --bind-to none $LOAM run bench/$scene.yaml --quiet --threads 1 --overwrite \
      --out "$OUT/b"
    $LOAM run bench/$scene.yaml --quiet --threads 2 --overwrite --out "$OUT/c"
    echo "$scene round $round: 1x1 $(rate "$OUT/a")  2 ranks x1 $(rate "$OUT/b")  1x2 threads $(rate "$OUT/c")"
  done
done
rm -rf "$OUT"
