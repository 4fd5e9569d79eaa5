#!/usr/bin/env bash
# diefill split over MPI ranks against LIGGGHTS 3.8 on two ranks, side by side on the settled
# pack of the reference scene (as compare_liggghts.sh): each repeat runs, interleaved, LIGGGHTS
# at -np 2, diefill on one process (one thread) and diefill at -np 2 (one thread each). Writes
# every run to bench/results/mpi_SIZE.csv and medians, the ratio to LIGGGHTS, the parallel
# efficiency from 1 to 2 ranks and the bytes per grain (ghosts included) to
# bench/results/mpi_SIZE.json.
#   bench/compare_mpi.sh [SIZE=50k] [REPEATS=5] [STEPS=3000]
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
size="${1:-50k}"; repeats="${2:-5}"; steps="${3:-3000}"
source "$root/bench/liggghts_pack.sh"
mpi=(mpirun --allow-run-as-root --oversubscribe -np 2)
csv="$root/bench/results/mpi_$size.csv"
echo "repeat,code,ranks,particle_steps_per_s,bytes_per_particle,largest_share_of_grains_with_ghosts,ghost_bytes_per_step" > "$csv"
diefill_run() {  # repeat ranks launcher...
  local k=$1 ranks=$2; shift 2
  OMP_NUM_THREADS=1 "$@" "$root/build/diefill" bench liggghts --pack runs/$tag.packed.dump --stl stl/$tag.stl --steps "$steps" \
    --threads 1 --cache "$work/cache" --json "$work/mpi_${size}_${ranks}_$k.json" 2>/dev/null
  python3 - "$work/mpi_${size}_${ranks}_$k.json" "$k" "$ranks" >> "$csv" <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))["cases"][0]["runs"][0]
print(f'{sys.argv[2]},diefill,{sys.argv[3]},{r["particle_steps_per_s"]},{r["bytes_per_particle"]},'
      f'{r.get("largest_share_of_grains_with_ghosts", 1.0)},{r.get("ghost_bytes_per_step", 0)}')
PY
}
for k in $(seq 1 "$repeats"); do
  loop=$("${mpi[@]}" liggghts -in in/bench.in -var wallfile in/wall_mesh.in -var stl stl/$tag.stl -var R $R \
           -var state runs/$tag.packed.restart -var nsteps "$steps" | awk '/^Loop time/ {print $4}')
  echo "$k,liggghts,2,$(python3 -c "print($N*$steps/$loop)"),,," >> "$csv"
  diefill_run "$k" 1
  diefill_run "$k" 2 "${mpi[@]}"
done
python3 - "$csv" > "$root/bench/results/mpi_$size.json" <<'PY'
import csv, json, statistics, sys
rows = list(csv.DictReader(open(sys.argv[1])))
def med(code, ranks, field="particle_steps_per_s"):
    v = [float(r[field]) for r in rows if r["code"] == code and int(r["ranks"]) == ranks]
    return {"median": statistics.median(v), "min": min(v), "max": max(v), "runs": len(v)}
out = {"liggghts_2_ranks": med("liggghts", 2), "diefill_1_rank": med("diefill", 1), "diefill_2_ranks": med("diefill", 2)}
out["ratio_to_liggghts_2_ranks"] = out["diefill_2_ranks"]["median"] / out["liggghts_2_ranks"]["median"]
out["parallel_efficiency_1_to_2"] = out["diefill_2_ranks"]["median"] / (2 * out["diefill_1_rank"]["median"])
for f in ("bytes_per_particle", "largest_share_of_grains_with_ghosts", "ghost_bytes_per_step"):
    out[f + "_2_ranks"] = med("diefill", 2, f)["median"]
print(json.dumps(out, indent=2))
PY
cat "$root/bench/results/mpi_$size.json"
