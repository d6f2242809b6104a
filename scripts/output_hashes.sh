#!/usr/bin/env bash
# Prints the sha256 of every mesh `vertexflow enhance` and `vertexflow batch` write for the
# modes and option variants the CLI tests use, on the bundled meshes: run it before and after a
# restructuring and diff the two lists (issue 27: "same bytes as before").
#
#   scripts/output_hashes.sh [BUILD_DIR] > hashes.txt
#
# Meshes only: reports hold timings. Runs with --quiet; a failing run prints "FAILED" in place of
# its hash, so a mode that starts or stops failing shows in the diff too.
set -uo pipefail
cd "$(dirname "$0")/.."
build=${1:-build}
cli="$build/bin/vertexflow"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

run() {  # name, arguments after IN OUT
  local name=$1 input=$2
  shift 2
  local out="$work/out.ply"
  if "$cli" --quiet enhance "$input" "$out" "$@" >/dev/null 2>&1; then
    echo "$(sha256sum <"$out" | cut -c1-64)  $name"
  else
    echo "FAILED  $name"
  fi
  rm -f "$out"
}

for mesh in bunny_uniform fandisk spot max-planck-5k sphere_low hemisphere suzanne chamfer-cube torus camelhead; do
  file=$(ls data/$mesh.* | head -1)
  run "$mesh.flow" "$file"
  run "$mesh.smooth" "$file" --surface smooth
  run "$mesh.unsharp" "$file" --method unsharp
done
u=data/bunny_uniform.off
for variant in "--lambda 2" "--mu 2" "--iterations 2" "--density-passes 5" "--density-passes 3 --density-exponent 1" \
  "--min-quality 0.1" "--sliver-floor 0.8" "--sliver-stiffness 0" "--no-projection" "--fairness zero" \
  "--feature-angle 60" "--free-boundary" "--solver direct" "--solver iterative" "--solver multilevel" \
  "--edge-flips" "--surface smooth --edge-flips" "--surface smooth --max-rounds 2" \
  "--surface smooth --assume-on-surface" "--surface smooth --feature-angle 60" \
  "--method unsharp --weight 0.5 --smoothing-iterations 3" \
  "--reference data/bunny.off" "--reference data/bunny.off --max-rounds 2" \
  "--reference data/bunny.off --edge-flips" "--reference data/bunny.off --edge-flips --flip-cycles 3" \
  "--reference data/bunny.off --reference-method flow" "--reference data/bunny.off --reference-method flow --lambda 2" \
  "--reference data/bunny.off --min-quality 0.2"; do
  # shellcheck disable=SC2086
  run "bunny_uniform $variant" "$u" $variant
done
run "bunny_adaptive.reference" data/bunny_adaptive.off --reference data/bunny.off
run "bunny_adaptive.smooth" data/bunny_adaptive.off --surface smooth
run "amo_adaptive.reference-flow" data/amo_adaptive.off --reference data/amo.off --reference-method flow
run "hemisphere.free-boundary" data/hemisphere.off --free-boundary
printf '0\n5\n17\n' >"$work/pins.txt"
run "spot.pins" data/spot.obj --pin "$work/pins.txt"

# batch over a directory of small meshes: every output's hash
mkdir -p "$work/in"
cp data/sphere_low.off data/spot.obj data/fertility.off data/suzanne.obj "$work/in/"
if "$cli" --quiet batch "$work/in" "$work/batch" >/dev/null 2>&1; then
  for f in "$work"/batch/*; do
    case "$f" in *batch_summary*) continue ;; esac
    echo "$(sha256sum <"$f" | cut -c1-64)  batch/$(basename "$f")"
  done
else
  echo "FAILED  batch"
fi
