#!/usr/bin/env bash
# Installs refray's build dependencies from Debian 12 packages (run as root).
# Idempotent: only missing packages are installed, so a second run costs seconds.
set -euo pipefail

packages=(
  build-essential cmake ninja-build pkg-config
  libembree-dev libopenimageio-dev openimageio-tools libglm-dev libtbb-dev
  googletest libgtest-dev libgmock-dev libbenchmark-dev
  libcli11-dev libtinyobjloader-dev
  libssl-dev  # OpenSSL's libcrypto: SHA-256 of scene files (core/hash.cpp)
  libboost-dev  # Boost.Math (headers): Student's t distribution of 'refray compare --statistical'
  chromium  # the compare tool's HTML report is checked in headless Chromium
  fonts-dejavu-core  # legends of index maps (refray render --aov) are drawn with DejaVu Sans
  clang libclang-rt-14-dev  # libFuzzer programs (tools/fuzz.sh)
  parallel  # the README's example of running 'refray sweep --emit-jobs' lines (a test runs it)
  python3  # tools/make_discrimination_report.sh and the GPU round's scripts write their tables with it
  slurm-wlm munge  # a single-node Slurm cluster runs the lines of 'refray golden update --emit-jobs' (a test starts it)
  libvulkan-dev glslang-tools spirv-tools  # the Vulkan back end (gpu/): headers, loader, GLSL -> SPIR-V, spirv-val
)

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "setup: all ${#packages[@]} packages present"
  exit 0
fi

if [ "$(id -u)" -ne 0 ]; then
  echo "setup: missing packages: ${missing[*]}" >&2
  echo "setup: run as root (or install them with apt-get) and try again" >&2
  exit 1
fi

echo "setup: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
apt-get update -qq
apt-get install -y -qq --no-install-recommends "${missing[@]}"
