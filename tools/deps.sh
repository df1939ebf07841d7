#!/usr/bin/env bash
# Installs the Debian 12 packages cnccomp needs, only those missing (apt-get; run as root).
set -euo pipefail
packages=(cmake ninja-build g++ pkg-config libeigen3-dev libnlopt-cxx-dev libtinyxml2-dev libfmt-dev libcli11-dev
          libgtest-dev libgmock-dev libbenchmark-dev clang libclang-rt-14-dev
          chromium)  # chromium: the HTML report's browser test (skipped without it)
# Installed without their recommends: linuxcnc-uspace (the real LinuxCNC 2.9, the oracle of tests/linuxcnc) recommends
# a real-time kernel, Qt and its documentation; the tests run only its simulator (34 MB download). linuxcnc-uspace-dev:
# halcompile and LinuxCNC's headers, which compile the generated kinematics component in the tests.
lean=(linuxcnc-uspace linuxcnc-uspace-dev)
missing=(); missing_lean=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
for p in "${lean[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing_lean+=("$p")
done
if ((${#missing[@]} + ${#missing_lean[@]})); then
  echo "installing: ${missing[*]} ${missing_lean[*]}"
  SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  $SUDO apt-get update -qq
  if ((${#missing[@]})); then DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq "${missing[@]}"; fi
  if ((${#missing_lean[@]})); then
    DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing_lean[@]}"
  fi
fi
