#!/usr/bin/env bash
# Side-by-side speed of diefill and LIGGGHTS 3.8 on the reference scene of
# ../shared/bench/liggghts: the same settled pack (prepared by LIGGGHTS), the same container
# STL, contact law (Hertz, tangential history, constant directional torque rolling 0.1) and
# time step (1 µs). Each repeat runs, interleaved: LIGGGHTS on one core and on two MPI ranks,
# diefill on one and two threads. Writes every run to bench/results/liggghts_SIZE.csv and the
# medians, spreads, per-core ratios and per-round ratios (bench/rounds_summary.py) to
# bench/results/liggghts_SIZE.json.
#   bench/compare_liggghts.sh [SIZE=5k|50k] [REPEATS=5] [STEPS=15000]
# Needs the Debian packages liggghts, openscad and openmpi-bin (installed when missing).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
size="${1:-5k}"; repeats="${2:-5}"; steps="${3:-15000}"
source "$root/bench/liggghts_pack.sh"
mpi=(mpirun --allow-run-as-root --oversubscribe -np 2)
csv="$root/bench/results/liggghts_$size.csv"
mkdir -p "$root/bench/results"
echo "repeat,code,threads,particle_steps_per_s" > "$csv"
for k in $(seq 1 "$repeats"); do
  echo "$k,liggghts,1,$(liggghts_rate stl/$tag.stl)" >> "$csv"
  echo "$k,liggghts,2,$(liggghts_rate stl/$tag.stl "${mpi[@]}")" >> "$csv"
  diefill_rates "$k" "$csv" "$work/diefill_${size}_$k.json"
done
python3 "$root/bench/rounds_summary.py" "$csv" liggghts "$work/diefill_${size}_1.json" \
  > "$root/bench/results/liggghts_$size.json"
cat "$root/bench/results/liggghts_$size.json"
