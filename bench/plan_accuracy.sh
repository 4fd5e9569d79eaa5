#!/usr/bin/env bash
# `diefill plan`'s predicted wall times against runs, out of sample: a fresh cache (the kernel
# measured afresh, no timed run yet: the model's defaults), the plan's prediction for each bundled
# die at each α, then the run itself. Prints one JSON object, also written to
# bench/results/plan_accuracy.json.
#   bench/plan_accuracy.sh [ALPHAS]      default: 16 11.3
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
alphas=${1:-"16 11.3"}
"$root/scripts/setup.sh" diefill >&2
work="$root/out/bench/plan_accuracy"
rm -rf "$work" && mkdir -p "$work"
rows=""
for die in ring disc; do
  "$root/build/diefill" plan "$root/dies/$die.stl" --out "$work/plan" --json "$work/plan_$die.json" >&2
  for a in $alphas; do
    start=$(date +%s.%N)
    "$root/build/diefill" run "$root/dies/$die.stl" --set "powder.coarse_graining=$a" --out "$work/$die$a" >&2
    wall=$(echo "$(date +%s.%N) - $start" | bc)
    rows+="$die $a $wall\n"
  done
done
printf "$rows" | /usr/bin/python3 -c '
import json, sys
work, root = sys.argv[1:]
out = {"command": "bench/plan_accuracy.sh", "runs": []}
for line in sys.stdin:
    die, alpha, wall = line.split()
    plan = json.load(open(f"{work}/plan_{die}.json"))
    level = next(l for l in plan["levels"] if abs(l["coarse_graining"] - float(alpha)) < 1e-9)
    out["runs"].append({"die": die, "coarse_graining": float(alpha), "predicted_s": level["predicted_wall_s"],
                        "measured_s": float(wall), "ratio": float(wall) / level["predicted_wall_s"]})
out["within_30_percent"] = all(abs(r["ratio"] - 1) <= 0.3 for r in out["runs"])
json.dump(out, open(f"{root}/bench/results/plan_accuracy.json", "w"), indent=2)
print(json.dumps(out))' "$work" "$root"
