#!/usr/bin/env bash
# Installs, from Debian's packages, whatever floedem needs that is missing.
# Idempotent: does nothing (and needs no root) when everything is there.
# Works as root or through sudo.
set -euo pipefail

packages=(
  build-essential cmake pkg-config clang
  libeigen3-dev libode-dev libbullet-dev libbox2d-dev libmujoco-dev libcgal-dev
  libhdf5-dev hdf5-tools libnetcdf-dev libproj-dev libgdal-dev catch2 libtomlplusplus-dev libcli11-dev libbenchmark-dev
  python3 python3-numpy python3-scipy python3-h5py python3-matplotlib python3-pytest python3-netcdf4 python3-pyproj
  # Films (floedem animate) and ParaView's reader, which the tests read the XDMF export back with.
  ffmpeg python3-paraview
  # Sweeps and the report's runs are launched by Snakemake.
  snakemake
)

missing=()
for p in "${packages[@]}"; do
  # dpkg-query prints "install ok installed" only for a fully installed package.
  if [ "$(dpkg-query -W -f='${Status}' "$p" 2>/dev/null)" != "install ok installed" ]; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "setup: all ${#packages[@]} packages present"
  exit 0
fi

echo "setup: installing ${missing[*]}"
if [ "$(id -u)" -eq 0 ]; then
  sudo_cmd=()
elif command -v sudo >/dev/null 2>&1; then
  sudo_cmd=(sudo)
else
  echo "setup: missing packages (${missing[*]}) and neither root nor sudo available" >&2
  exit 1
fi
export DEBIAN_FRONTEND=noninteractive
"${sudo_cmd[@]}" apt-get update -qq
"${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
