#!/usr/bin/env bash
# Throughput against grain count: beds of 5k to 500k grains tiled from the settled 50k pack of
# the LIGGGHTS reference scene (the same powder in the same state at every size; `diefill bench
# scaling`), each timed REPEATS times on one thread. Writes every run to
# bench/results/scaling.csv, the medians to bench/results/scaling.json and the chart to
# docs/scaling.png.
#   bench/scaling.sh [REPEATS=3] [STEPS=2000]
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
repeats="${1:-3}"; steps="${2:-2000}"; size=50k
source "$root/bench/liggghts_pack.sh"
sizes=(5000 15000 50000 150000 500000)
csv="$root/bench/results/scaling.csv"
echo "repeat,grains,particle_steps_per_s,bytes_per_particle" > "$csv"
for k in $(seq 1 "$repeats"); do
  "$root/build/diefill" bench scaling --pack "runs/$tag.packed.dump" $(printf -- '--sizes %s ' "${sizes[@]}") \
    --threads 1 --steps "$steps" --json "$work/scaling_$k.json" 2>/dev/null
  python3 - "$work/scaling_$k.json" "$k" >> "$csv" <<'PY'
import json, sys
for case in json.load(open(sys.argv[1]))["cases"]:
    run = case["runs"][0]
    print(f'{sys.argv[2]},{case["grains"]},{run["particle_steps_per_s"]},{run["bytes_per_particle"]}')
PY
done
# Debian's Python, which has matplotlib (scripts/setup.sh), whatever python3 the PATH finds first.
/usr/bin/python3 - "$csv" "$root/bench/results/scaling.json" "$root/docs/scaling.png" <<'PY'
import csv, json, statistics, sys
import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt
rows = list(csv.DictReader(open(sys.argv[1])))
sizes = sorted({int(r["grains"]) for r in rows})
out = {"threads": 1, "sizes": []}
for n in sizes:
    rates = sorted(float(r["particle_steps_per_s"]) for r in rows if int(r["grains"]) == n)
    out["sizes"].append({"grains": n, "median": statistics.median(rates), "min": rates[0], "max": rates[-1],
                         "bytes_per_particle": float(next(r["bytes_per_particle"] for r in rows if int(r["grains"]) == n))})
first = out["sizes"][0]["median"]
out["largest_fall_from_smallest"] = max(0.0, 1 - min(s["median"] for s in out["sizes"]) / first)
json.dump(out, open(sys.argv[2], "w"), indent=2)
fig, ax = plt.subplots(figsize=(6, 4))
ax.errorbar(sizes, [s["median"] / 1e6 for s in out["sizes"]],
            yerr=[[(s["median"] - s["min"]) / 1e6 for s in out["sizes"]], [(s["max"] - s["median"]) / 1e6 for s in out["sizes"]]],
            fmt="o-", capsize=3, label="diefill, 1 thread (median, min-max)")
ax.axhline(0.75 * first / 1e6, ls="--", color="grey", label="25 % below the 5k rate")
ax.set_xscale("log"); ax.set_ylim(bottom=0)
ax.set_xlabel("grains"); ax.set_ylabel("million particle-steps per second"); ax.legend(); ax.grid(alpha=0.3)
ax.set_title("Throughput against grain count (settled bed, Hertz + CDT)")
fig.tight_layout(); fig.savefig(sys.argv[3], dpi=120)
print(json.dumps(out, indent=2))
PY
