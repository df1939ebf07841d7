#!/usr/bin/env bash
# Installs the Debian 12 packages cnccomp needs, only those missing (apt-get; run as root).
set -euo pipefail
packages=(cmake ninja-build g++ pkg-config libeigen3-dev libnlopt-cxx-dev libtinyxml2-dev libfmt-dev libcli11-dev
          libgtest-dev libgmock-dev libbenchmark-dev clang libclang-rt-14-dev linuxcnc-uspace)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  echo "installing: ${missing[*]}"
  SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq "${missing[@]}"
fi
