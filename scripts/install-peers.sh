#!/usr/bin/env bash
# Installs the peer engines bench/peers compares appell with (idempotent):
# Simbody 3.7, MuJoCo 2.2.2 and Siconos 4.4, all as Debian packages. Optional: the normal
# build neither needs nor looks for more than their presence (bench/peers/).
set -euo pipefail

PACKAGES=(
  libsimbody-dev   # Simbody 3.7: exact constraints, Constraint::Custom rolling rows
  libmujoco-dev    # MuJoCo 2.2.2: soft frictional contact
  libsiconos-kernel-dev  # Siconos 4.4: Moreau–Jean time-stepping (report_peers_vehicles;
                         # pulls libsiconos-numerics-dev, its fc3d solvers)
)

bash "$(dirname "$0")/apt-install.sh" install-peers "${PACKAGES[@]}"
echo "install-peers: re-run cmake so bench/peers finds them"
