#!/usr/bin/env bash
# Installs the Debian 12 packages veil needs to build, test and render
# headless (Mesa llvmpipe through EGL). Idempotent: silent when everything is
# present. Run by a user who is not root, it prints the exact command to run
# and stops.
set -euo pipefail

packages=(
  gcc make cmake pkg-config
  libepoxy-dev libegl-dev libegl1 libegl-mesa0 libgl1-mesa-dri   # EGL + GL 4.5 (llvmpipe)
  libcglm-dev libopenexr-dev libpng-dev libcjson-dev
  g++ libopenvdb-dev libboost-dev libtbb-dev                     # the OpenVDB reader (io/vdb.cpp)
  libnanovdb-dev                                                 # .nvdb files (headers only, io/vdb.cpp)
  time                                                           # /usr/bin/time: tests bound a refusal's memory
  python3 python3-numpy python3-pytest python3-openvdb           # the Python module and its tests (docs/python.md)
  python3-setuptools python3-wheel python3-pip python3-venv      # pip install of python/ into a venv (tests/python)
  python3-openimageio                                            # reads deep EXRs back as a compositor does (tests/cli/deep_cli.sh)
)

missing=()
for p in "${packages[@]}"; do
  status=$(dpkg-query -W -f='${Status}' "$p" 2>/dev/null || true)
  [ "$status" = "install ok installed" ] || missing+=("$p")
done
[ ${#missing[@]} -eq 0 ] && exit 0

if [ "$(id -u)" -ne 0 ]; then
  echo "veil needs these Debian packages: ${missing[*]}" >&2
  echo "install them with:" >&2
  echo "  sudo apt-get update && sudo apt-get install -y ${missing[*]}" >&2
  exit 1
fi

echo "installing: ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
apt-get update -q >/dev/null
apt-get install -y -q --no-install-recommends "${missing[@]}" >/dev/null
echo "installed ${#missing[@]} packages"
