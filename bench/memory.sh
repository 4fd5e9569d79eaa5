#!/usr/bin/env bash
# Memory per grain, diefill beside LIGGGHTS and LAMMPS, on the settled 5k and 50k packs of the
# reference scene (the packs, inputs and laws of compare_liggghts.sh and compare_lammps.sh).
# - The peers: the growth of the process's peak resident set (GNU time's %M) from the 5k pack to
#   the 50k pack, over the 45,000 grains more; one core, 10 steps. What a grain costs them,
#   whatever else the process holds.
# - diefill: the peak resident set from its state's creation on, per grain (`diefill bench
#   liggghts`: the allocator's rounding, the rebuild's scratch and the threads' buffers included; the
#   run ends with one rebuild), and the state's arrays per grain, on the 50k pack, one and two
#   threads. Not the 5k pack's: its 5 MB of state sit within what the allocator keeps from the
#   set-up. The same at 500k grains: bench/scaling.sh.
# Writes bench/results/memory.json.
#   bench/memory.sh
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
steps=10
command -v /usr/bin/time >/dev/null || DEBIAN_FRONTEND=noninteractive apt-get install -y -qq time >/dev/null
for size in 5k 50k; do
  source "$root/bench/liggghts_pack.sh"
  source "$root/bench/lammps_pack.sh"
  liggghts_rate "stl/$tag.stl" /usr/bin/time -f %M -o "$work/memory_liggghts_$size.kB" >/dev/null
  lammps_rate "$work/memory_lammps_$size.log" /usr/bin/time -f %M -o "$work/memory_lammps_$size.kB" >/dev/null
done
"$root/build/diefill" bench liggghts --pack "runs/$tag.packed.dump" --stl "stl/$tag.stl" --steps 100 \
  --threads 1 --threads 2 --cache "$work/cache" --json "$work/memory_diefill_50k.json" 2>/dev/null
mkdir -p "$root/bench/results"
python3 - "$work" > "$root/bench/results/memory.json" <<'PY'
import json, sys
work = sys.argv[1]
kB = lambda code, size: float(open(f"{work}/memory_{code}_{size}.kB").read().split()[-1])
peers = {code: {"peak_resident_kB_5k": kB(code, "5k"), "peak_resident_kB_50k": kB(code, "50k"),
                "bytes_per_grain": (kB(code, "50k") - kB(code, "5k")) * 1024 / 45000}
         for code in ("liggghts", "lammps")}
runs = json.load(open(f"{work}/memory_diefill_50k.json"))["cases"][0]["runs"]
diefill = {"pack": "50k",
           "peak_resident_bytes_per_grain": {str(r["threads"]): r["peak_resident_bytes_per_particle"] for r in runs},
           "arrays_bytes_per_grain": runs[-1]["bytes_per_particle"]}
print(json.dumps({"peers_5k_to_50k": peers, "diefill": diefill}, indent=2))
PY
cat "$root/bench/results/memory.json"
