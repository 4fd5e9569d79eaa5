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
/usr/bin/python3 - "$work" "$die" "$levels" "$next" "$ladder_s" "$next_s" "$root" <<'PY'
import json, math, shutil, sys
work, die, levels, nxt, ladder_s, next_s, root = sys.argv[1:]
e = json.load(open(f"{work}/ladder/{die}/report.json"))["extrapolation"]
f = json.load(open(f"{work}/next/{die}/report.json"))["fill"]
run_se = f.get("fill_ratio_stderr", None)
out = {"command": f"bench/ladder.sh {die} {levels} {nxt}", "die": die, "ladder": levels, "next": float(nxt),
       "extrapolated": e["fill_ratio"], "extrapolated_stderr": e["fill_ratio_stderr"], "chi2": e["chi2"],
       "run": f["fill_ratio"], "run_stderr": run_se, "difference": e["fill_ratio"] - f["fill_ratio"],
       "ladder_wall_s": int(ladder_s), "run_wall_s": int(next_s)}
if run_se is not None:
    out["within_two_combined_stderr"] = abs(out["difference"]) <= 2 * math.hypot(e["fill_ratio_stderr"], run_se)
json.dump(out, open(f"{root}/bench/results/ladder_{die}.json", "w"), indent=2)
shutil.copy(f"{work}/ladder/{die}/extrapolation.png", f"{root}/docs/ladder_{die}.png")
print(json.dumps(out))
PY
