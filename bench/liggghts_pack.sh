# Sourced by the benchmarks (compare_liggghts.sh, compare_lammps.sh, scaling.sh, ...) with $root
# and $size (5k or 50k) set: installs what the reference scene of ../shared/bench/liggghts needs,
# builds diefill, prepares the container STLs and the settled pack (by LIGGGHTS, once; kept under
# out/bench/liggghts/runs), and leaves the shell in that work folder with R, H, N, tag set and
# liggghts_rate and diefill_rates defined.
ref="${DIEFILL_LIGGGHTS_DIR:-$root/../shared/bench/liggghts}"
work="${DIEFILL_BENCH_WORK:-$root/out/bench/liggghts}"
for p in liggghts openscad mpirun; do
  command -v "$p" >/dev/null || { DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends liggghts openscad openmpi-bin >/dev/null; }
done
"$root/scripts/setup.sh" diefill >&2
mkdir -p "$work"
cp -r "$ref/in" "$ref/scad" "$ref/make_stl.sh" "$work/"
cd "$work"
[[ -f stl/n50k_plain128.stl ]] || bash make_stl.sh >/dev/null 2>&1
case "$size" in
  5k) R=0.010; H=0.040; N=5000; insH=0.033; tag=n5k_plain128 ;;
  50k) R=0.022; H=0.070; N=50000; insH=0.065; tag=n50k_plain128 ;;
  *) echo "size must be 5k or 50k" >&2; exit 2 ;;
esac
mkdir -p runs
if [[ ! -f runs/$tag.packed.dump ]]; then
  echo "preparing the settled pack with LIGGGHTS ($N grains, once)..." >&2
  liggghts -in in/prep.in -var wallfile in/wall_mesh.in -var stl stl/$tag.stl -var R $R -var H $H -var N $N \
    -var insH $insH -var prepdt 5e-6 -var tag $tag -var maxsteps 200000 > prep_$tag.log
fi

# LIGGGHTS' particle-steps per second over $steps steps of the settled pack in the container STL
# given, run by the launcher that follows it (none: one core; mpirun ...: ranks).
liggghts_rate() {  # STL [launcher...]
  local stl=$1 loop
  shift
  loop=$("$@" liggghts -in in/bench.in -var wallfile in/wall_mesh.in -var stl "$stl" -var R $R \
           -var state runs/$tag.packed.restart -var nsteps "$steps" | awk '/^Loop time/ {print $4}')
  python3 -c "print($N*$steps/$loop)"
}

# diefill's particle-steps per second over $steps steps of the same pack in the container STL, on
# one and two threads (`diefill bench liggghts`, its JSON kept as given): appends the rows
# "REPEAT,diefill,THREADS,RATE" to the CSV given.
diefill_rates() {  # REPEAT CSV JSON
  local k=$1 csv=$2 json=$3
  "$root/build/diefill" bench liggghts --pack runs/$tag.packed.dump --stl stl/$tag.stl --steps "$steps" \
    --threads 1 --threads 2 --cache "$work/cache" --json "$json" 2>/dev/null
  python3 - "$json" "$k" >> "$csv" <<'PY'
import json, sys
for run in json.load(open(sys.argv[1]))["cases"][0]["runs"]:
    print(f'{sys.argv[2]},diefill,{run["threads"]},{run["particle_steps_per_s"]}')
PY
}
