# Sourced after bench/liggghts_pack.sh, with $steps set: LAMMPS (Debian's `lammps`, installed
# when missing), the settled pack of $tag as a LAMMPS data file ($data), and lammps_rate defined.
command -v lmp >/dev/null || DEBIAN_FRONTEND=noninteractive apt-get install -y -qq lammps >/dev/null
warm=$(( steps / 10 < 200 ? steps / 10 : 200 ))  # untimed steps first, as diefill's warm-up

# The settled pack as a LAMMPS data file (atom_style sphere): the positions of
# runs/$tag.packed.dump, grains at rest and without contact history, as diefill reads it.
data=runs/$tag.lammps.data
if [[ ! -f $data || runs/$tag.packed.dump -nt $data ]]; then
  python3 - runs/$tag.packed.dump "$data" <<'PY'
import sys
lines = open(sys.argv[1]).read().splitlines()
box = lines[lines.index(next(l for l in lines if l.startswith("ITEM: BOX BOUNDS"))) + 1:][:3]
at = next(i for i, l in enumerate(lines) if l.startswith("ITEM: ATOMS"))
cols = lines[at].split()[2:]
rows = [dict(zip(cols, l.split())) for l in lines[at + 1:] if l.strip()]
with open(sys.argv[2], "w") as out:
    out.write(f"LAMMPS data file of {sys.argv[1]} (grains at rest; density 2500 kg/m3)\n\n")
    out.write(f"{len(rows)} atoms\n1 atom types\n\n")
    for b, axis in zip(box, "xyz"):
        lo, hi = b.split()[:2]
        out.write(f"{lo} {hi} {axis}lo {axis}hi\n")
    out.write("\nAtoms # sphere\n\n")
    for r in rows:
        out.write(f'{r["id"]} 1 {2 * float(r["radius"])!r} 2500 {r["x"]} {r["y"]} {r["z"]}\n')
PY
fi

# LAMMPS' particle-steps per second over $steps steps of the pack, its output kept in LOG, run by
# the launcher that follows (none: one core; mpirun ...: ranks).
lammps_rate() {  # LOG [launcher...]
  local log=$1 loop
  shift
  OMP_NUM_THREADS=1 "$@" lmp -in "$root/bench/lammps/bench.in" -log none -var data "$data" -var R $R -var H $H \
    -var warm $warm -var nsteps "$steps" > "$log"
  loop=$(awk '/^Loop time/ {t = $4} END {print t}' "$log")
  [[ -n $loop ]] || { echo "LAMMPS gave no loop time: see $log" >&2; return 1; }
  python3 -c "print($N*$steps/$loop)"
}
