#!/usr/bin/env bash
# Installs every build, test and benchmark dependency of vertexflow from Debian 12 packages.
# Idempotent: when everything is already installed it changes nothing and touches no network.
set -euo pipefail

packages=(
  build-essential cmake ninja-build pkg-config git
  libeigen3-dev            # dense/sparse linear algebra, V/F matrices
  libsuitesparse-dev       # CHOLMOD sparse Cholesky (flow solver)
  libmetis-dev             # fill-reducing ordering for CHOLMOD
  libopenblas0-pthread     # BLAS for CHOLMOD supernodal
  libtbb-dev               # parallel loops
  libcgal-dev              # polygon triangulation, AABB trees, remeshing, QEM
  libgmp-dev libmpfr-dev   # CGAL's exact kernels
  libcli11-dev             # command-line parsing
  libfmt-dev               # formatting
  nlohmann-json3-dev       # JSON output
  zlib1g-dev               # gzip-compressed meshes
  libosmesa6-dev           # off-screen software OpenGL (llvmpipe) for `vertexflow render`
  libpng-dev               # PNG output of renders
  libfreetype-dev fonts-dejavu-core  # colour-bar labels in renders
  libgtest-dev libgmock-dev
  libbenchmark-dev
  clang libclang-rt-14-dev # libFuzzer targets and sanitizers
  clang-format
)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done

if [ ${#missing[@]} -eq 0 ]; then
  exit 0
fi

echo "setup: installing ${missing[*]}" >&2
SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
