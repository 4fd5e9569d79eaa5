#!/usr/bin/env bash
# The speed-accuracy study redrawn against the real powder's answer (issue 45): each setting's
# fill ratio of the ring (bench/results/speed_accuracy_default.csv, `diefill study speed-accuracy`
# at the default size) against the ring's extrapolated real-powder fill ratio (the ladder of
# bench/results/ladder_ring.json, `bench/ladder.sh ring …`), beside what `diefill plan` predicts
# for a grain size: its time on this machine and its error, the wall layer's bias and one seed's
# noise combined (docs/PHYSICS.md §4.2). Prints one JSON object, also written to
# bench/results/speed_accuracy_real.json; the chart to docs/speed_accuracy_real.png.
#   bench/speed_accuracy_real.sh
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
"$root/scripts/setup.sh" diefill >&2
work="$root/out/bench/speed_accuracy_real"
mkdir -p "$work"
"$root/build/diefill" plan "$root/dies/ring.stl" --out "$work" --json "$work/plan_ring.json" >&2
/usr/bin/python3 - "$root" "$work" <<'PY'
import csv, json, math, sys
import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt
root, work = sys.argv[1:]
real = json.load(open(f"{root}/bench/results/ladder_ring.json"))["real_powder"]
plan = json.load(open(f"{work}/plan_ring.json"))
truth, truth_se = real["fill_ratio"], real["fill_ratio_stderr"]
def distance(level):  # the plan's expected distance of one seed from the real powder
    return math.hypot(level["bias"], level["fill_ratio_stderr_one_seed"])
rows = [r for r in csv.DictReader(open(f"{root}/bench/results/speed_accuracy_default.csv")) if r["outcome"] == "ran"]
runs = []
for r in rows:  # the plan grid rounds α to three digits (11.3 for 8√2)
    alpha = float(r["coarse_graining"])
    level = next((l for l in plan["levels"] if abs(l["coarse_graining"] / alpha - 1) < 5e-3), None)
    plain = (float(r["stiffness_factor"]) == 1 and abs(float(r["time_step_fraction"]) - 0.15) < 1e-9 and
             abs(float(r["die_voxel_fraction"]) - 0.25) < 1e-9)
    run = {"setting": r["setting"], "group": r["group"], "coarse_graining": alpha, "wall_s": float(r["wall_s"]),
           "fill_ratio": float(r["fill_ratio"]), "error_against_real_powder": float(r["fill_ratio"]) - truth}
    if level is not None and plain:  # the plan models the grain size, not softening, the step or the wall voxels
        run["plan_predicted_wall_s"] = level["predicted_wall_s"]
        run["plan_bias"] = -level["bias"]  # the plan's fill minus the real powder's
        run["plan_seed_stderr"] = level["fill_ratio_stderr_one_seed"]
        run["plan_predicted_distance"] = distance(level)
    runs.append(run)
out = {"command": "bench/speed_accuracy_real.sh", "real_powder_fill_ratio": truth, "real_powder_fill_ratio_stderr": truth_se,
       "real_powder_from": "bench/results/ladder_ring.json", "runs": runs}
json.dump(out, open(f"{root}/bench/results/speed_accuracy_real.json", "w"), indent=2)

fig, ax = plt.subplots(figsize=(7, 4.5))
for group in dict.fromkeys(r["group"] for r in runs):
    xs = [r["wall_s"] for r in runs if r["group"] == group]
    ys = [100 * abs(r["error_against_real_powder"]) for r in runs if r["group"] == group]
    ax.scatter(xs, ys, label=f"{group} (measured)")
levels = sorted((l for l in plan["levels"] if l["coarse_graining"] >= 4), key=lambda l: l["predicted_wall_s"])
ax.plot([l["predicted_wall_s"] for l in levels],
        [100 * distance(l) for l in levels], "k--", label="plan: one seed per grain size")
for l in levels:
    ax.annotate(f"α {l['coarse_graining']:.3g}", (l["predicted_wall_s"], 100 * distance(l)),
                fontsize=7, textcoords="offset points", xytext=(3, 3))
ax.axhspan(0, 100 * truth_se, color="0.85", label="real powder's answer: its standard error")
ax.set_xscale("log")
ax.set_xlabel("wall-clock time [s] (2 cores)")
ax.set_ylabel("|fill ratio − real powder's| [percentage points]")
ax.set_title(f"Ring die: distance from the real powder's fill ratio {truth:.3f} ± {truth_se:.3f}")
ax.legend(fontsize=7)
fig.tight_layout()
fig.savefig(f"{root}/docs/speed_accuracy_real.png", dpi=120)
print(json.dumps(out))
PY
