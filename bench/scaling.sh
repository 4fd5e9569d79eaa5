#!/usr/bin/env bash
# Throughput against grain count: beds of 5k to 500k grains tiled from the settled 50k pack of
# the LIGGGHTS reference scene and settled again as tiled, so that every size is the same powder at
# rest (`diefill bench scaling`; each bed is settled once and kept in out/bench), each timed
# REPEATS times on one and on two threads, each size in a process of its own (its peak resident
# set is its own). The contacts per grain at the start and the end of the timed steps show that
# the bed did not change while it was timed. Writes every run to bench/results/scaling.csv (rate, the
# arrays' bytes per grain, the peak resident bytes per grain with the rebuild's scratch and the
# allocator's rounding, one rebuild's time over a step's), the medians to
# bench/results/scaling.json and the chart to docs/scaling.png.
# SIZES: the grain counts to time (default all five). A bed not yet settled is settled first: all
# five took about 50 minutes of both cores on an Intel Xeon kind, the 500k bed alone is over an
# hour on an AMD EPYC Zen 1. With `unsettled`, a bed of several tiles is timed as laid out of the
# settled tiles, not settled again (`--unsettled-beds`: minutes instead of an hour); the contacts
# per grain at the start and the end of the timed steps say how far it moved.
#   bench/scaling.sh [REPEATS=3] [STEPS=2000] [SIZES="5000 15000 50000 150000 500000"] [unsettled]
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
repeats="${1:-3}"; steps="${2:-2000}"; size=50k
read -r -a sizes <<< "${3:-5000 15000 50000 150000 500000}"
unsettled=()
case "${4:-}" in
  unsettled) unsettled=(--unsettled-beds) ;;
  "") ;;
  *) echo "scaling.sh: the fourth argument is 'unsettled' or nothing, not '$4'" >&2; exit 2 ;;
esac
source "$root/bench/liggghts_pack.sh"
csv="$root/bench/results/scaling.csv"
echo "repeat,grains,threads,particle_steps_per_s,bytes_per_particle,peak_resident_bytes_per_particle,rebuild_over_step,neighbour_builds,contacts_per_grain_at_start,contacts_per_grain,bed_settled" > "$csv"
for k in $(seq 1 "$repeats"); do
  for n in "${sizes[@]}"; do
    "$root/build/diefill" bench scaling --pack "runs/$tag.packed.dump" --sizes "$n" \
      --threads 1 --threads 2 --steps "$steps" --cache "$root/out/bench" "${unsettled[@]}" --json "$work/scaling_${k}_$n.json" 2>/dev/null
    python3 - "$work/scaling_${k}_$n.json" "$k" >> "$csv" <<'PY'
import json, sys
for case in json.load(open(sys.argv[1]))["cases"]:
    for run in case["runs"]:
        print(f'{sys.argv[2]},{case["grains"]},{run["threads"]},{run["particle_steps_per_s"]},{run.get("bytes_per_particle", "")},'
              f'{run["peak_resident_bytes_per_particle"]},{run["rebuild_over_step"]},{run["neighbour_builds"]},'
              f'{run["contacts_per_grain_at_start"]},{run["contacts_per_grain"]},{int(case["bed_settled"])}')
PY
  done
done
# Debian's Python, which has matplotlib (scripts/setup.sh), whatever python3 the PATH finds first.
/usr/bin/python3 - "$csv" "$root/bench/results/scaling.json" "$root/docs/scaling.png" <<'PY'
import csv, json, statistics, sys
import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt
rows = list(csv.DictReader(open(sys.argv[1])))
sizes = sorted({int(r["grains"]) for r in rows})
out = {"threads": [1, 2]}
for t in (1, 2):
    mine = [r for r in rows if int(r["threads"]) == t]
    cases = []
    for n in sizes:
        at = [r for r in mine if int(r["grains"]) == n]
        rates = sorted(float(r["particle_steps_per_s"]) for r in at)
        cases.append({"grains": n, "median": statistics.median(rates), "min": rates[0], "max": rates[-1],
                      "per_core_median": statistics.median(rates) / t,
                      "rebuild_over_step_median": statistics.median(float(r["rebuild_over_step"]) for r in at),
                      "peak_resident_bytes_per_particle_max": max(float(r["peak_resident_bytes_per_particle"]) for r in at),
                      "neighbour_builds_max": max(int(r["neighbour_builds"]) for r in at),
                      "contacts_per_grain_at_start_median": statistics.median(float(r["contacts_per_grain_at_start"]) for r in at),
                      "contacts_per_grain_at_end_median": statistics.median(float(r["contacts_per_grain"]) for r in at),
                      "bed_settled": all(r["bed_settled"] == "1" for r in at),
                      **({"bytes_per_particle": float(at[0]["bytes_per_particle"])} if at[0]["bytes_per_particle"] else {})})
    first = cases[0]["median"]
    # Each size's rate over the smallest size's, within each round (the host moves between rounds).
    rate = {(r["repeat"], int(r["grains"])): float(r["particle_steps_per_s"]) for r in mine}
    rounds = sorted({k for k, _ in rate}, key=int)
    per_round = {str(n): [rate[k, n] / rate[k, sizes[0]] for k in rounds if (k, n) in rate and (k, sizes[0]) in rate] for n in sizes[1:]}
    out[f"threads_{t}"] = {"sizes": cases, "largest_fall_from_smallest": max(0.0, 1 - min(c["median"] for c in cases) / first),
                           "per_round_over_smallest": {n: {"rounds": r, "median": statistics.median(r), "min": min(r)} for n, r in per_round.items()}}
json.dump(out, open(sys.argv[2], "w"), indent=2)
fig, ax = plt.subplots(figsize=(6, 4))
for t in (1, 2):
    cases = out[f"threads_{t}"]["sizes"]
    ax.errorbar(sizes, [c["per_core_median"] / 1e6 for c in cases],
                yerr=[[(c["median"] - c["min"]) / t / 1e6 for c in cases], [(c["max"] - c["median"]) / t / 1e6 for c in cases]],
                fmt="o-", capsize=3, label=f"diefill, {t} thread{'s' if t > 1 else ''} (per core: median, min-max)")
ax.axhline(0.9 * out["threads_1"]["sizes"][0]["median"] / 1e6, ls="--", color="grey", label="10 % below the 5k rate (1 thread)")
ax.set_xscale("log"); ax.set_ylim(bottom=0)
ax.set_xlabel("grains"); ax.set_ylabel("million particle-steps per second per core"); ax.legend(); ax.grid(alpha=0.3)
ax.set_title("Throughput against grain count (beds at rest, Hertz + CDT)")
fig.tight_layout(); fig.savefig(sys.argv[3], dpi=120)
print(json.dumps(out, indent=2))
PY
