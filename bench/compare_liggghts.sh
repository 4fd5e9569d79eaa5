#!/usr/bin/env bash
# Side-by-side speed of diefill and LIGGGHTS 3.8 on the reference scene of
# ../shared/bench/liggghts: the same settled pack (prepared by LIGGGHTS), the same container
# STL, contact law (Hertz, tangential history, constant directional torque rolling 0.1) and
# time step (1 µs). Each repeat runs, interleaved: LIGGGHTS on one core and on two MPI ranks,
# diefill on one and two threads. Writes every run to bench/results/liggghts_SIZE.csv and the
# medians, spreads and per-core ratios to bench/results/liggghts_SIZE.json.
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
  "$root/build/diefill" bench liggghts --pack runs/$tag.packed.dump --stl stl/$tag.stl --steps "$steps" \
    --threads 1 --threads 2 --cache "$work/cache" --json "$work/diefill_${size}_$k.json" 2>/dev/null
  python3 - "$work/diefill_${size}_$k.json" "$k" >> "$csv" <<'PY'
import json, sys
for run in json.load(open(sys.argv[1]))["cases"][0]["runs"]:
    print(f'{sys.argv[2]},diefill,{run["threads"]},{run["particle_steps_per_s"]}')
PY
done
python3 - "$csv" "$(nproc)" "$(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2- | xargs)" "$work/diefill_${size}_1.json" \
  > "$root/bench/results/liggghts_$size.json" <<'PY'
import csv, json, statistics, sys
rows = list(csv.DictReader(open(sys.argv[1])))
first = json.load(open(sys.argv[4]))["cases"][0]
out = {"scene": sys.argv[1], "cores": int(sys.argv[2]), "cpu": sys.argv[3], "grains": first["grains"],
       "bytes_per_particle": first["runs"][-1].get("bytes_per_particle")}
for code in ("liggghts", "diefill"):
    for t in (1, 2):
        r = sorted(float(x["particle_steps_per_s"]) for x in rows if x["code"] == code and int(x["threads"]) == t)
        med = statistics.median(r)
        out[f"{code}_{t}"] = {"median": med, "min": r[0], "max": r[-1], "runs": len(r),
                              "largest_deviation_from_median": max(abs(x / med - 1) for x in r)}
for t in (1, 2):
    out[f"ratio_{t}"] = out[f"diefill_{t}"]["median"] / out[f"liggghts_{t}"]["median"]
print(json.dumps(out, indent=2))
PY
cat "$root/bench/results/liggghts_$size.json"
