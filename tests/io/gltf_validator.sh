#!/bin/sh
# The glTF the CLI writes passes the Khronos glTF Validator with 0 errors: each sample in
# data/gltf enhanced to .glb and .gltf, spot.obj written as a fresh .glb, and that spot.glb
# enhanced (where vertices move, with texture coordinates and normals re-sampled).
# usage: gltf_validator.sh CLI NODE SOURCE_DIR WORK_DIR
set -eu
cli=$1 node=$2 source=$3 work=$4
rm -rf "$work"
mkdir -p "$work"
for input in BoxTextured/BoxTextured.glb BoxTextured/BoxTextured.gltf MorphPrimitivesTest/MorphPrimitivesTest.gltf \
             SimpleSkin/SimpleSkin.gltf; do
  name=$(basename "$input" | tr . _)
  for extension in glb gltf; do
    mkdir -p "$work/$name-$extension"  # a .gltf's buffers and images are written beside it
    "$cli" enhance "$source/data/gltf/$input" "$work/$name-$extension/enhanced.$extension"
  done
done
"$cli" enhance "$source/data/spot.obj" "$work/spot.glb"
"$cli" enhance "$work/spot.glb" "$work/spot_enhanced.glb"
mkdir -p "$work/spot-gltf"
"$cli" enhance "$work/spot.glb" "$work/spot-gltf/spot_enhanced.gltf"
"$node" "$source/scripts/validate_gltf.mjs" "$work"/*.glb "$work"/*/enhanced.glb "$work"/*/enhanced.gltf "$work/spot-gltf/spot_enhanced.gltf"
