#!/usr/bin/env bash
# Installs exactly the Debian (bookworm) packages granflow's build, tests and plots need.
# Idempotent: does nothing when everything is present.
set -euo pipefail

packages=(
  cmake ninja-build ccache g++ make pkg-config
  libdeal.ii-dev            # deal.II 9.4: meshes, simplex FE, quadrature, VTU output
  libsuitesparse-dev        # CHOLMOD sparse Cholesky
  libgmsh-dev gmsh          # Gmsh C++ API for the built-in geometries
  nlohmann-json3-dev        # summary.json
  libgtest-dev              # unit and verification tests
  libbenchmark-dev          # bench/ micro benchmarks
  python3 python3-matplotlib python3-meshio python3-numpy python3-scipy  # scripts/plot, scripts/*.py
)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  exit 0
fi

echo "install-deps: installing ${missing[*]}"
SUDO=""
if [ "$(id -u)" -ne 0 ]; then
  command -v sudo >/dev/null || { echo "install-deps: need root or sudo to install packages" >&2; exit 1; }
  SUDO="sudo"
fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
echo "install-deps: done"
