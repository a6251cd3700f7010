#!/usr/bin/env bash
# Installs the Debian 12 packages the benchmarks and tools need beyond
# scripts/install-deps.sh: by default gnuplot (no X11) for bench/accuracy's
# time-error plot; with arguments, those packages instead (`make fuzz`:
# clang, whose libFuzzer tests/fuzz/ needs; `make peers`: libopenvdb-tools,
# OpenVDB's vdb_render and vdb_tool, which bench/peers.py measures against). Idempotent: silent when
# everything is present. Run by a user who is not root, it prints the exact
# command to run and stops.
set -euo pipefail

packages=(
  gnuplot-nox   # bench/accuracy: docs/results/accuracy*.png
)
[ $# -gt 0 ] && packages=("$@")

missing=()
for p in "${packages[@]}"; do
  status=$(dpkg-query -W -f='${Status}' "$p" 2>/dev/null || true)
  [ "$status" = "install ok installed" ] || missing+=("$p")
done
[ ${#missing[@]} -eq 0 ] && exit 0

if [ "$(id -u)" -ne 0 ]; then
  echo "the veil benchmarks and tools need these Debian packages: ${missing[*]}" >&2
  echo "install them with:" >&2
  echo "  sudo apt-get update && sudo apt-get install -y ${missing[*]}" >&2
  exit 1
fi

echo "installing: ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
apt-get update -q >/dev/null
apt-get install -y -q --no-install-recommends "${missing[@]}" >/dev/null
echo "installed ${#missing[@]} packages"
