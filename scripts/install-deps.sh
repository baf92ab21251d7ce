#!/usr/bin/env bash
# Installs everything appell needs on a fresh Debian machine (idempotent).
# Every dependency is a Debian package; nothing is downloaded at build time.
set -euo pipefail

PACKAGES=(
  build-essential cmake ninja-build pkg-config
  clang                  # scripts/test.sh compiles its builds with clang (README, Building)
  libeigen3-dev          # Eigen 3.4: dense linear algebra
  libfcl-dev libccd-dev  # FCL 0.7 + libccd: collision queries
  libqhull-dev           # Qhull: convex hulls of mesh contact shapes
  libtinyxml-dev         # TinyXML: the URDF and its <appell> scene block
  libassimp-dev          # assimp: STL / OBJ / Collada meshes
  libgtest-dev           # GoogleTest
  libbenchmark-dev       # Google Benchmark
  gnuplot-nox            # figures of the benchmark reports
  python3-dev pybind11-dev        # the Python bindings (python/)
  python3-numpy python3-pytest    # their arrays and their tests
  python3-pip python3-venv python3-setuptools python3-wheel  # pip install . (pyproject.toml)
  python3-distributed             # appell.sweep on a Dask cluster (python/appell/sweep.py)
)

bash "$(dirname "$0")/apt-install.sh" install-deps "${PACKAGES[@]}"
