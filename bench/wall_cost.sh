#!/usr/bin/env bash
# Wall cost against tessellation: the settled 5k pack of the LIGGGHTS reference scene
# (../shared/bench/liggghts) in the same cylinder as four STLs, from 508 triangles to a million
# (plain128; plain1024, 4,092 slivers; struct1024, 120,832 well-shaped; struct1m, 978,944), timed
# on one thread by `diefill bench liggghts` and, interleaved, by LIGGGHTS 3.8 on one core (which
# aborts at setup on the million-triangle mesh: recorded, not timed); then the SDF build of the
# million-triangle container (`diefill sdf`, no cache, all cores). Writes every run to
# bench/results/wall_cost.csv and medians, spreads and the SDF time to bench/results/wall_cost.json.
#   bench/wall_cost.sh [REPEATS=3] [STEPS=5000]
# Needs the Debian packages liggghts, openscad and openmpi-bin (installed when missing).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
repeats="${1:-3}"; steps="${2:-5000}"; size=5k
source "$root/bench/liggghts_pack.sh"
containers=(plain128 plain1024 struct1024 struct1m)
csv="$root/bench/results/wall_cost.csv"
mkdir -p "$root/bench/results"
echo "repeat,code,container,triangles,particle_steps_per_s" > "$csv"
for k in $(seq 1 "$repeats"); do
  for c in "${containers[@]}"; do
    stl="stl/n5k_$c.stl"
    "$root/build/diefill" bench liggghts --pack runs/$tag.packed.dump --stl "$stl" --steps "$steps" --threads 1 \
      --cache "$work/cache" --json "$work/wall_cost_${c}_$k.json" 2>/dev/null
    python3 - "$work/wall_cost_${c}_$k.json" "$k" "$c" >> "$csv" <<'PY'
import json, sys
case = json.load(open(sys.argv[1]))["cases"][0]
print(f'{sys.argv[2]},diefill,{sys.argv[3]},{case["container_triangles"]},{case["runs"][0]["particle_steps_per_s"]}')
PY
    [[ "$c" == struct1m ]] && continue  # LIGGGHTS 3.8 aborts at setup on it (../shared/bench/liggghts/README.md)
    echo "$k,liggghts,$c,,$(liggghts_rate "$stl")" >> "$csv"
  done
done
start=$(date +%s.%N)
"$root/build/diefill" sdf stl/n5k_struct1m.stl --role container --grain-radius 0.5 --voxel 0.25 \
  -o "$work/struct1m.vdb" > "$work/struct1m_sdf.log" 2>&1
sdf_s=$(python3 -c "print($(date +%s.%N) - $start)")
python3 - "$csv" "$sdf_s" "$(nproc)" "$(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2- | xargs)" \
  > "$root/bench/results/wall_cost.json" <<'PY'
import csv, json, statistics, sys
rows = list(csv.DictReader(open(sys.argv[1])))
out = {"scene": "5k settled pack, 1 thread / 1 core", "cores": int(sys.argv[3]), "cpu": sys.argv[4],
       "sdf_build_s_struct1m": float(sys.argv[2]), "containers": {}}
for c in ("plain128", "plain1024", "struct1024", "struct1m"):
    entry = {}
    for code in ("diefill", "liggghts"):
        r = sorted(float(x["particle_steps_per_s"]) for x in rows if x["code"] == code and x["container"] == c)
        if r:
            entry[code] = {"median": statistics.median(r), "min": r[0], "max": r[-1], "runs": len(r)}
    entry["triangles"] = int(next(x["triangles"] for x in rows if x["code"] == "diefill" and x["container"] == c))
    out["containers"][c] = entry
medians = [e["diefill"]["median"] for e in out["containers"].values()]
out["diefill_slowest_over_fastest"] = min(medians) / max(medians)
print(json.dumps(out, indent=2))
PY
cat "$root/bench/results/wall_cost.json"
