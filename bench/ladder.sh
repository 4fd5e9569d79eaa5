#!/usr/bin/env bash
# A grain-size ladder against a finer run (docs/PHYSICS.md §4.1, issue 45): the ladder's
# extrapolation to the finer level's α beside that level run directly, and the refusal where the
# die's features are too thin for the ladder. Prints one JSON object and writes it to
# bench/results/ladder_<die>.json; the chart to docs/ladder_<die>.png.
#   bench/ladder.sh DIE LEVELS NEXT [SEEDS_OF_NEXT]     e.g. bench/ladder.sh disc 22.6,16,11.3 8 1
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
die=$1 levels=$2 next=$3 seeds=${4:-1}
"$root/scripts/setup.sh" diefill >&2
work="$root/out/bench/ladder_$die"
rm -rf "$work" && mkdir -p "$work"
start=$(date +%s)
"$root/build/diefill" run "$root/dies/$die.stl" --ladder "$levels" --extrapolate-to "$next" --out "$work/ladder" >&2
ladder_s=$(($(date +%s) - start)) start=$(date +%s)
if [[ $seeds -gt 1 ]]; then
  "$root/build/diefill" run "$root/dies/$die.stl" --seeds "$seeds" --set "powder.coarse_graining=$next" --out "$work/next" >&2
else
  "$root/build/diefill" run "$root/dies/$die.stl" --set "powder.coarse_graining=$next" --out "$work/next" >&2
fi
next_s=$(($(date +%s) - start))
/usr/bin/python3 - "$work" "$die" "$levels" "$next" "$seeds" "$ladder_s" "$next_s" "$root" <<'PY'
import json, math, shutil, sys
work, die, levels, nxt, seeds, ladder_s, next_s, root = sys.argv[1:]
e = json.load(open(f"{work}/ladder/{die}/report.json"))["extrapolation"]
nrep = json.load(open(f"{work}/next/{die}/report.json"))
f = nrep["fill"]
run_se, run_se_source = f.get("fill_ratio_stderr", None), "the next level's own seeds"
if run_se is None:
    # One seed: its error from the ladder's seed noise, pooled over its levels and scaled by the
    # grains in the cavity (docs/PHYSICS.md §4.1): each level's stderr is sigma / sqrt(G n).
    import csv
    rows = list(csv.DictReader(open(f"{work}/ladder/{die}/ladder.csv")))
    sigma = math.sqrt(sum(float(r["fill_ratio_stderr"]) ** 2 * float(r["grains_in_cavity"]) * int(r["seeds"]) for r in rows) / len(rows))
    run_se = sigma / math.sqrt(nrep["particles"]["in_cavity"])
    run_se_source = "the ladder's pooled seed noise over the run's grains in the cavity (docs/PHYSICS.md 4.1)"
out = {"command": f"bench/ladder.sh {die} {levels} {nxt} {seeds}", "die": die, "ladder": levels, "next": float(nxt),
       "extrapolated": e["fill_ratio"], "extrapolated_stderr": e["fill_ratio_stderr"], "chi2": e["chi2"],
       "chi2_limit": e["chi2_limit"], "refused": e["refused"], "real_powder": e.get("real_powder"),
       "run": f["fill_ratio"], "run_stderr": run_se, "run_stderr_from": run_se_source, "run_seeds": int(seeds),
       "difference": e["fill_ratio"] - f["fill_ratio"],
       "ladder_wall_s": int(ladder_s), "run_wall_s": int(next_s)}
out["combined_stderr"] = math.hypot(e["fill_ratio_stderr"], run_se)
out["within_two_combined_stderr"] = abs(out["difference"]) <= 2 * out["combined_stderr"]
out["ladder_stderr_at_most_0.005"] = e["fill_ratio_stderr"] <= 0.005
json.dump(out, open(f"{root}/bench/results/ladder_{die}.json", "w"), indent=2)
shutil.copy(f"{work}/ladder/{die}/extrapolation.png", f"{root}/docs/ladder_{die}.png")
print(json.dumps(out))
PY
