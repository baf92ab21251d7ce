#!/usr/bin/env bash
# Installs the peer engines bench/peers compares appell with (idempotent):
# Simbody 3.7 and MuJoCo 2.2.2, both as Debian packages. Optional: the normal
# build neither needs nor looks for more than their presence (bench/peers/).
set -euo pipefail

PACKAGES=(
  libsimbody-dev   # Simbody 3.7: exact constraints, Constraint::Custom rolling rows
  libmujoco-dev    # MuJoCo 2.2.2: soft frictional contact
)

missing=()
for p in "${PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "install-peers: all ${#PACKAGES[@]} packages present"
  exit 0
fi

SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
echo "install-peers: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${PACKAGES[@]}" >/dev/null
echo "install-peers: done (re-run cmake so bench/peers finds them)"
