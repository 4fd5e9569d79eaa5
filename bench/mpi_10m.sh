#!/usr/bin/env bash
# Ten million grains over MPI ranks (docs/ARCHITECTURE.md, "Domain decomposition"): a lattice bed
# of GRAINS grains (`diefill bench mpi-bed`: each rank builds only its own slab) stepped 100 steps
# on RANKS ranks (one thread each; oversubscribed here, so times are not speeds), a checkpoint
# written at step 50 and the particle output (VTU pieces) at the end; the checkpoint resumed on
# RANKS ranks (the same state hash at step 100 as the uninterrupted run) and on 3 (the same
# grains and momentum at resume); then a small bed on 1 to 16 ranks for the messages and bytes
# each rank sends per step (counts, not times). Writes bench/results/mpi_10m.json.
#   bench/mpi_10m.sh [GRAINS=10000000] [RANKS=4] [SMALL_GRAINS=200000]
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
grains="${1:-10000000}"; ranks="${2:-4}"; small="${3:-200000}"
work="$root/out/bench/mpi_10m"
rm -rf "$work" && mkdir -p "$work"
bed() {  # ranks json [options...]
  local n=$1 json=$2; shift 2
  mpirun --allow-run-as-root --oversubscribe -np "$n" -x OMP_NUM_THREADS=1 "$root/build/diefill" bench mpi-bed --threads 1 \
    --json "$json" "$@"
}
start=$(date +%s)
bed "$ranks" "$work/run.json" --grains "$grains" --steps 100 --checkpoint-at 50 --cache "$work"
checkpoint="$work/mpi-bed/checkpoint.bin"
bed "$ranks" "$work/resumed_same.json" --grains "$grains" --steps 100 --resume "$checkpoint" --cache "$work/resumed_same"
bed 3 "$work/resumed_3.json" --grains "$grains" --steps 100 --resume "$checkpoint" --cache "$work/resumed_3"
du -sb "$work/mpi-bed" > "$work/disk.txt"
rm -rf "$work/mpi-bed"  # gigabytes: the checkpoint and the particle output, measured above
for n in 1 2 4 8 16; do
  bed "$n" "$work/small_$n.json" --grains "$small" --steps 50 --cache "$work/small_$n"
done
python3 - "$work" "$grains" "$ranks" "$small" "$(( $(date +%s) - start ))" > "$root/bench/results/mpi_10m.json" <<'PY'
import json, sys
work, grains, ranks, small, wall = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), int(sys.argv[4]), int(sys.argv[5])
case = lambda name: json.load(open(f"{work}/{name}.json"))["cases"][0]
run, same, three = case("run"), case("resumed_same"), case("resumed_3")
written, resumed = run["census_at_checkpoint"], three["census_at_resume"]
# The resumed run sums the momentum of the same grains in another order: equal to the rounding of
# a sum of `grains` terms, grains * 2^-53 of the sum of their magnitudes.
tolerance = grains * 2.0**-53 * written["momentum_scale"]
momentum_gap = max(abs(a - b) for a, b in zip(written["momentum"], resumed["momentum"]))
keys = ["setup_s", "step_s", "checkpoint_s", "particle_output_s", "particle_steps_per_s", "rebuilds", "cuts",
        "state_bytes_per_owned_grain", "messages_per_rank_per_step", "bytes_per_rank_per_step"]
out = {
    "command": f"bench/mpi_10m.sh {grains} {ranks} {small}",
    "grains": run["grains"], "ranks": run["ranks"], "steps": run["steps"],
    "bytes_per_owned_grain": run["bytes_per_owned_grain"],
    "global_collectives_per_step": run["global_collectives_per_step"],
    "resumed_on_3_ranks": resumed["grains"] == written["grains"] and momentum_gap <= tolerance,
    "resumed_on_3_ranks_momentum_gap": momentum_gap, "resumed_on_3_ranks_momentum_tolerance": tolerance,
    "same_state_hash_resumed_on_same_ranks": same["state_hash"] == run["state_hash"],
    "run": {k: run[k] for k in keys},
    "resumed_on_same_ranks": {k: same[k] for k in keys + ["bytes_per_owned_grain", "global_collectives_per_step"]},
    "resumed_on_3_ranks_run": {k: three[k] for k in keys + ["bytes_per_owned_grain", "global_collectives_per_step"]},
    "end_grains_on_3_ranks": three["census_at_end"]["grains"],
    "checkpoint_and_output_bytes": int(open(f"{work}/disk.txt").read().split()[0]),
    "small_bed": [{"ranks": c["ranks"], "grains": c["grains"],
                   "global_collectives_per_step": c["global_collectives_per_step"],
                   "messages_per_rank_per_step": c["messages_per_rank_per_step"],
                   "bytes_per_rank_per_step": c["bytes_per_rank_per_step"]}
                  for c in (case(f"small_{n}") for n in (1, 2, 4, 8, 16))],
    "wall_s": wall,
}
print(json.dumps(out, indent=2))
PY
cat "$root/bench/results/mpi_10m.json"
