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
  libsleef-dev  # SLEEF: float's sin, cos, acos, atan, exp2, log2 in the shader ports, 8 lanes a call (procedural/math/transcendentals.h)
  libboost-dev  # Boost.Math (headers): Student's t distribution of 'refray compare --statistical'
  chromium  # the compare tool's HTML report is checked in headless Chromium
  fonts-dejavu-core  # legends of index maps (refray render --aov) are drawn with DejaVu Sans
  clang libclang-rt-14-dev  # libFuzzer programs (tools/fuzz.sh)
  parallel  # the README's example of running 'refray sweep --emit-jobs' lines (a test runs it)
  python3  # tools/make_discrimination_report.sh and the GPU round's scripts write their tables with it
  slurm-wlm munge  # a single-node Slurm cluster runs the lines of 'refray golden update --emit-jobs' (a test starts it)
  libvulkan-dev glslang-tools spirv-tools  # the Vulkan back end (gpu/): headers, loader, GLSL -> SPIR-V, spirv-val
  ccache  # every preset compiles through it (CMakePresets.json); its cache lives outside the clone (~/.cache/ccache)
)

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "setup: all ${#packages[@]} packages present"
else
  if [ "$(id -u)" -ne 0 ]; then
    echo "setup: missing packages: ${missing[*]}" >&2
    echo "setup: run as root (or install them with apt-get) and try again" >&2
    exit 1
  fi
  echo "setup: installing ${missing[*]}"
  export DEBIAN_FRONTEND=noninteractive
  apt-get update -qq
  apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

# Mesa's lavapipe: a CPU Vulkan driver with VK_KHR_ray_tracing_pipeline and VK_KHR_ray_query
# (Mesa >= 25 from Debian's bookworm-backports). The Lavapipe* tests run refray's Vulkan back end on it.
bash "$(dirname "$0")/setup_lavapipe.sh"

# ccache keeps the objects of every preset (ci and asan-ubsan builds of one commit are about 3 GB).
if command -v ccache >/dev/null 2>&1; then
  current=$(ccache -k max_size 2>/dev/null || echo "")
  if [ "$current" != "20.0G" ] && [ "$current" != "20.0 GB" ] && [ "$current" != "20G" ]; then
    ccache --max-size 20G >/dev/null && echo "setup: ccache max size set to 20G"
  fi
fi
