#!/usr/bin/env bash
# Our recursive coordinate bisection beside Zoltan's RCB (bench/partition.cpp) on two scenes: the
# settled 50k pack of ../shared/bench/liggghts (uniform) and the bundled ring die after the
# default fill (powder left in the shoe above a full cavity: far from uniform), each split over
# 2, 3, 4 and 8 ranks. Writes one JSON line per case to bench/results/partition.jsonl.
#   bench/compare_partition.sh
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
size=50k
(source "$root/bench/liggghts_pack.sh")  # the settled pack, prepared once by LIGGGHTS
"$root/scripts/setup.sh" diefill partition >&2
work="$root/out/bench/partition"
mkdir -p "$work"
awk 'BEGIN {print "id,x,y,z,vx,vy,vz,wx,wy,wz,radius"}
     /^ITEM: ATOMS/ {for (i = 3; i <= NF; i++) c[$i] = i - 2; atoms = 1; next}
     atoms && NF >= 5 {printf "%s,%s,%s,%s,0,0,0,0,0,0,%s\n", $c["id"], $c["x"], $c["y"], $c["z"], $c["radius"]}' \
  "$root/out/bench/liggghts/runs/n50k_plain128.packed.dump" > "$work/pack50k.csv"
[[ -f "$work/ring/ring/particles.csv" ]] || "$root/build/diefill" run "$root/dies/ring.stl" --out "$work/ring" >&2
out="$root/bench/results/partition.jsonl"
: > "$out"
for scene in "$work/pack50k.csv" "$work/ring/ring/particles.csv"; do
  for ranks in 2 3 4 8; do
    OMP_NUM_THREADS=1 mpirun --oversubscribe --allow-run-as-root -np "$ranks" "$root/build/bench/partition" "$scene" | tee -a "$out"
  done
done
