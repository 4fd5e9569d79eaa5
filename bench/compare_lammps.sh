#!/usr/bin/env bash
# Side-by-side speed of diefill and LAMMPS (Debian's `lammps`, 29 Sep 2021, pair_style granular)
# on the reference scene of ../shared/bench/liggghts, as compare_liggghts.sh does for LIGGGHTS:
# the same settled pack (prepared by LIGGGHTS, converted to a LAMMPS data file), grains, Hertz
# normal law with the same realised restitution, Mindlin tangential history, gravity, time step
# (1 µs) and skin, in bench/lammps/bench.in. What LAMMPS cannot match (its container is an
# analytic cylinder, its rolling law a spring-slider) is listed under "differences" in the JSON.
# Each repeat runs, interleaved: LAMMPS on one core and on two MPI ranks, diefill on one and two
# threads. Writes every run to bench/results/lammps_SIZE.csv and the medians, spreads and
# ratios, per thread count and per round (bench/rounds_summary.py), to
# bench/results/lammps_SIZE.json; LAMMPS' own output to out/bench/liggghts/lammps_SIZE_*.log.
#   bench/compare_lammps.sh [SIZE=5k|50k] [REPEATS=5] [STEPS=15000]
# Needs the Debian packages lammps, liggghts, openscad and openmpi-bin (installed when missing).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
size="${1:-5k}"; repeats="${2:-5}"; steps="${3:-15000}"
source "$root/bench/liggghts_pack.sh"
source "$root/bench/lammps_pack.sh"
mpi=(mpirun --allow-run-as-root --oversubscribe -np 2)

csv="$root/bench/results/lammps_$size.csv"
mkdir -p "$root/bench/results"
echo "repeat,code,threads,particle_steps_per_s" > "$csv"
for k in $(seq 1 "$repeats"); do
  rate=$(lammps_rate "$work/lammps_${size}_1_$k.log"); echo "$k,lammps,1,$rate" >> "$csv"
  rate=$(lammps_rate "$work/lammps_${size}_2_$k.log" "${mpi[@]}"); echo "$k,lammps,2,$rate" >> "$csv"
  diefill_rates "$k" "$csv" "$work/diefill_lammps_${size}_$k.json"
done

# The state of both codes at the end of round 1 on one core: LAMMPS' thermo of the timed run
# (kinetic energies, contacts per grain, grains outside the container) and neighbour statistics
# (half list: pairs listed once, so x2 for pairs per grain), diefill's counters.
health=$(python3 - "$work/lammps_${size}_1_1.log" "$work/diefill_lammps_${size}_1.json" <<'PY'
import json, re, sys
text = open(sys.argv[1]).read()
run = text.split("Step Atoms c_tke")[-1].split("Loop time")[0].split("\n")[1:]
thermo = [list(map(float, l.split())) for l in run if re.match(r"\s*\d", l)]
last = lambda pattern: float(re.findall(pattern, text)[-1])
d = json.load(open(sys.argv[2]))["cases"][0]["runs"][0]
print(json.dumps({
    "lammps": {"atoms_end": int(thermo[-1][1]), "largest_kinetic_energy_J": max(r[2] for r in thermo),
               "largest_rotational_energy_J": max(r[3] for r in thermo), "contacts_per_grain_end": thermo[-1][4],
               "largest_grains_outside_container": int(max(r[5] for r in thermo)),
               "listed_pairs_per_grain": 2 * last(r"Ave neighs/atom = (\S+)"),
               "neighbour_builds": int(last(r"Neighbor list builds = (\d+)"))},
    "diefill": {k: d.get(k) for k in ("contacts_per_grain", "listed_pairs_per_grain", "neighbour_builds",
                                      "wall_contacts", "near_wall_grains")}}))
PY
)
differences=(
  "container: no STL or mesh walls for granular contacts in LAMMPS 29 Sep 2021 (fix wall/gran takes planes, a z cylinder or a region), so an analytic cylinder (fix wall/gran/region on region cylinder R, closed at z = 0, open top); diefill and LIGGGHTS use the 128-facet STL of that cylinder, whose flat facets lie up to R(1 - cos(pi/128)) = 0.03 % of R inside the circle"
  "container curvature: LAMMPS counts the concave side wall in the contact's effective radius (R* = r 2R/(2R - r): +2.6 % at R = 10 mm, +1.1 % at 22 mm); diefill's and LIGGGHTS' mesh facets are flat (R* = r)"
  "wall stiffness: this LAMMPS' wall fix takes E* = E/(2(1 - nu)) for hertz/material, 30 % stiffer than its pair style's E/(2(1 - nu^2)); the wall is given E/(1 + nu) to get the grains' E* (checked: a grain at rest on the floor sinks 0.291 um, Hertz's value)"
  "rolling: LAMMPS has no constant directional torque law; rolling sds (spring k_roll = 2 N/m, diefill's EPSD stiffness 2.25 mu_r^2 S_n at 1 um overlap, no damping, slider at mu_r R* F_n, the CDT torque's limit) keeps 3 more history values per contact; diefill and LIGGGHTS use CDT (no rolling history)"
  "damping: damping tsuji, gamma_n = alpha sqrt(m* k_n) with k_n = 4/3 E* sqrt(R* delta), diefill's form (gamma_n proportional to sqrt(m* S_n)); LAMMPS' alpha(e) polynomial realises e = 0.646 in a Hertz collision when given 0.5, so it is given e = 0.2964, whose alpha is diefill's calibrated coefficient (realised e = 0.49998 grain on grain, 0.49997 grain on floor); limit_damping keeps the normal force repulsive, as diefill"
  "tangential: Mindlin with k_t = 8 G* a given explicitly and gamma_t = sqrt(2(1 - nu)/(2 - nu)) gamma_n, as diefill; LAMMPS' Coulomb cap uses the damped normal force, as diefill"
  "two cores: LAMMPS on two MPI ranks (domain split sideways, processors * * 1; the Debian build has no OPENMP package), diefill on two OpenMP threads in one process"
  "start: both start from the dump's positions at rest without contact history (LIGGGHTS' own runs restart with velocities and histories); both run min(200, STEPS/10) untimed steps first"
)
args=(--note "steps=$steps" --note "lammps_version=$(lmp -h | sed -n 's/.*Simulator - //p')"
      --note "health_round_1_one_core=$health")
for d in "${differences[@]}"; do args+=(--difference "$d"); done
python3 "$root/bench/rounds_summary.py" "$csv" lammps "$work/diefill_lammps_${size}_1.json" "${args[@]}" \
  > "$root/bench/results/lammps_$size.json"
cat "$root/bench/results/lammps_$size.json"
