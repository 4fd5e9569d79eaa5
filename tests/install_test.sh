#!/usr/bin/env bash
# An installed diefill runs away from the source tree: installed into a fresh prefix, the prefix
# moved elsewhere, run from /tmp, `diefill run` writes its report and pictures from its own
# share/diefill (its --version names where its data is).
#   tests/install_test.sh BUILD_DIR DIE_MESH
set -euo pipefail
build="$1"; die="$2"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
cmake --install "$build" --prefix "$tmp/prefix" > /dev/null
mv "$tmp/prefix" "$tmp/moved"
name="$(basename "$die" .stl)"
cp "$die" "$tmp/$name.stl"
cd /tmp
data="$("$tmp/moved/bin/diefill" --version | sed -n 's/^  data: //p')"
if [[ "$data" != "$tmp/moved/share/diefill"* ]]; then
  echo "install_test: the installed diefill reads its data from '$data', not from its prefix" >&2
  exit 1
fi
"$tmp/moved/bin/diefill" run "$tmp/$name.stl" --out "$tmp/out" --set powder.coarse_graining=22.6 \
  --set motion.speed=0.4 --set motion.die_settle_time=0.01
for file in report.json density.vdb top_view.png sections.png histogram.png; do
  [[ -s "$tmp/out/$name/$file" ]] || { echo "install_test: $file is missing" >&2; exit 1; }
done
echo "install_test: passed"
