#!/usr/bin/env bash
# Installs every build, test and benchmark dependency of vertexflow from Debian 12 packages.
# Idempotent: when everything is already installed it changes nothing and touches no network.
set -euo pipefail

packages=(
  build-essential cmake ninja-build pkg-config git
  libeigen3-dev            # dense/sparse linear algebra, V/F matrices
  libsuitesparse-dev       # CHOLMOD sparse Cholesky (flow solver)
  libmetis-dev             # fill-reducing ordering for CHOLMOD
  libopenblas0-serial      # BLAS for CHOLMOD supernodal, one thread (CMakeLists.txt says why)
  libopenblas0-pthread     # threaded BLAS, only for the test that results do not depend on BLAS threads
  libtbb-dev               # parallel loops
  libcgal-dev              # polygon triangulation, AABB trees, remeshing, QEM
  libjemalloc-dev          # the CLI's allocator, with transparent huge pages (apps/allocator.cpp)
  libboost-dev             # Boost headers used directly (the native QEM's d-ary heap); CGAL needs them too
  libgmp-dev libmpfr-dev   # CGAL's exact kernels
  libcli11-dev             # command-line parsing
  libfmt-dev               # formatting
  nlohmann-json3-dev       # JSON output
  libtinygltf-dev          # glTF 2.0 reading and writing (tiny_gltf.h; uses nlohmann-json3-dev)
  zlib1g-dev               # gzip-compressed meshes
  libosmesa6-dev           # off-screen software OpenGL (llvmpipe) for `vertexflow render`
  libpng-dev               # PNG output of renders
  libfreetype-dev fonts-dejavu-core  # colour-bar labels in renders
  libcairo2-dev            # anti-aliased strokes of line drawings (`vertexflow lines`)
  libgtest-dev libgmock-dev
  libbenchmark-dev
  libmeshoptimizer-dev     # meshoptimizer, the LoD peer of bench/lod_peers.cpp
  libembree-dev            # Embree 3, the point-query peer measured by bench/point_query_peers.cpp (only there)
  clang libclang-rt-14-dev # libFuzzer targets and sanitizers
  clang-format
  python3                  # bench/make_results.py (docs/results.md)
  python3-dev pybind11-dev python3-pybind11  # the Python module (python/)
  python3-numpy python3-pytest               # its API and test suite
  python3-dask python3-distributed           # examples/dask_batch.py and its test
  chromium chromium-driver # headless browser test of the HTML report (tests/CMakeLists.txt)
)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
# Node.js and npm build the HTML report's viewer (web/). A Node.js already on the machine counts
# (some builds bundle npm and conflict with Debian's npm package); otherwise Debian's.
if ! command -v node >/dev/null || ! command -v npm >/dev/null; then missing+=(nodejs npm); fi

if [ ${#missing[@]} -ne 0 ]; then
  echo "setup: installing ${missing[*]}" >&2
  SUDO=""
  if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -qq
  $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

# npm packages of web/ (three.js, esbuild, playwright-core, gltf-validator for
# scripts/validate_gltf.mjs) exactly as package-lock.json pins them; skipped when node_modules
# was installed from this very lock file.
web="$(cd "$(dirname "$0")/.." && pwd)/web"
stamp="$web/node_modules/.vertexflow-package-lock.json"
if ! cmp -s "$web/package-lock.json" "$stamp"; then
  echo "setup: npm ci in $web" >&2
  (cd "$web" && npm ci --no-audit --no-fund --loglevel=error)
  cp "$web/package-lock.json" "$stamp"
fi
