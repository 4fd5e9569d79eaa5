#!/usr/bin/env bash
# Side-by-side speed of diefill and LIGGGHTS 3.8 on the reference scene of
# ../shared/bench/liggghts: the same settled pack (prepared by LIGGGHTS), the same container
# STL, contact law (Hertz, tangential history, constant directional torque rolling 0.1) and
# time step (1 µs). Runs are interleaved and repeated; medians go to CSV and JSON.
#   bench/compare_liggghts.sh [N=5k|50k] [REPEATS=3] [STEPS=15000]
# Needs the Debian packages liggghts and openscad (installed when missing).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
size="${1:-5k}"; repeats="${2:-3}"; steps="${3:-15000}"
ref="${DIEFILL_LIGGGHTS_DIR:-$root/../shared/bench/liggghts}"
work="${DIEFILL_BENCH_WORK:-$root/out/bench/liggghts}"
for p in liggghts openscad; do
  command -v "$p" >/dev/null || { DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends "$p" >/dev/null; }
done
"$root/scripts/setup.sh" diefill >&2
mkdir -p "$work"
cp -r "$ref/in" "$ref/scad" "$ref/make_stl.sh" "$work/"
cd "$work"
[[ -d stl ]] || bash make_stl.sh >/dev/null 2>&1
case "$size" in
  5k) R=0.010; H=0.040; N=5000; insH=0.033; tag=n5k_plain128 ;;
  50k) R=0.022; H=0.070; N=50000; insH=0.065; tag=n50k_plain128 ;;
  *) echo "size must be 5k or 50k" >&2; exit 2 ;;
esac
mkdir -p runs
if [[ ! -f runs/$tag.packed.dump ]]; then
  echo "preparing the settled pack with LIGGGHTS ($N grains)..." >&2
  liggghts -in in/prep.in -var wallfile in/wall_mesh.in -var stl stl/$tag.stl -var R $R -var H $H -var N $N \
    -var insH $insH -var prepdt 5e-6 -var tag $tag -var maxsteps 200000 > prep_$tag.log
fi
csv="$root/bench/results/liggghts_$size.csv"
mkdir -p "$root/bench/results"
echo "repeat,code,threads,particle_steps_per_s" > "$csv"
for k in $(seq 1 "$repeats"); do
  loop=$(liggghts -in in/bench.in -var wallfile in/wall_mesh.in -var stl stl/$tag.stl -var R $R \
           -var state runs/$tag.packed.restart -var nsteps "$steps" | awk '/^Loop time/ {print $4}')
  echo "$k,liggghts,1,$(python3 -c "print($N*$steps/$loop)")" >> "$csv"
  "$root/build/diefill" bench liggghts --pack runs/$tag.packed.dump --stl stl/$tag.stl --steps "$steps" \
    --threads 1 --threads 2 --cache "$work/cache" --json "$work/diefill_$k.json" 2>/dev/null
  python3 - "$work/diefill_$k.json" "$k" >> "$csv" <<'PY'
import json, sys
for run in json.load(open(sys.argv[1]))["cases"][0]["runs"]:
    print(f'{sys.argv[2]},diefill,{run["threads"]},{run["particle_steps_per_s"]}')
PY
done
python3 - "$csv" "$(nproc)" "$(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2- | xargs)" <<'PY'
import csv, json, statistics, sys
rows = list(csv.DictReader(open(sys.argv[1])))
def median(code, threads):
    return statistics.median(float(r["particle_steps_per_s"]) for r in rows if r["code"] == code and int(r["threads"]) == threads)
lig = median("liggghts", 1)
out = {"scene": sys.argv[1], "cores": int(sys.argv[2]), "cpu": sys.argv[3], "liggghts_1core": lig}
for t in (1, 2):
    d = median("diefill", t)
    out[f"diefill_{t}threads"] = d
    out[f"ratio_per_core_{t}threads"] = d / t / lig
print(json.dumps(out, indent=2))
PY
