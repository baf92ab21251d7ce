#!/usr/bin/env bash
# Installs everything appell needs on a fresh Debian machine (idempotent).
# Every dependency is a Debian package; nothing is downloaded at build time.
set -euo pipefail

PACKAGES=(
  build-essential cmake ninja-build pkg-config
  libeigen3-dev          # Eigen 3.4: dense linear algebra
  libfcl-dev libccd-dev  # FCL 0.7 + libccd: collision queries
  libtinyxml-dev         # TinyXML: the URDF and its <appell> scene block
  libassimp-dev          # assimp: STL / OBJ / Collada meshes
  libgtest-dev           # GoogleTest
  libbenchmark-dev       # Google Benchmark
  gnuplot-nox            # figures of the benchmark reports
)

missing=()
for p in "${PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#PACKAGES[@]} packages present"
  exit 0
fi

SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
echo "install-deps: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${PACKAGES[@]}" >/dev/null
echo "install-deps: done"
