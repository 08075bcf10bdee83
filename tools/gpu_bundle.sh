#!/usr/bin/env bash
# Assembles .gpu-bundle/: what `refray render --device vulkan` needs on the GPU machine (Ubuntu 24.04, NVIDIA
# driver, no internet), built here on Debian 12. docs/vulkan-backend.md, "Running on the GPU machine".
#
#   .gpu-bundle/refray          the release binary (stripped)
#   .gpu-bundle/shaders/        the compiled GLSL ports: <library>/<Export>.<stage>.spv
#   .gpu-bundle/debs/*.deb      the Debian packages of the shared libraries refray uses (Embree, oneTBB,
#                               OpenImageIO, OpenEXR, libpng, ...), unpacked by tools/gpu_run.sh with `dpkg -x`
#                               into .gpu-bundle/lib (never into /)
#   .gpu-bundle/stand-ins/*.so.*    stand-ins of the format libraries OpenImageIO links but refray never calls
#                               (tools/gpu_bundle_libraries.py)
#   .gpu-bundle/gl/*.deb        the Vulkan loader and the glvnd set the NVIDIA ICD needs, unpacked into / there
#   .gpu-bundle/MANIFEST        what is in it, with sizes
#
# The packages travel as .debs (compressed) because unpacked they exceed what a device call carries (Embree
# alone is 43 MB). With --target-ldconfig FILE (the output of `ldconfig -p` on the GPU machine, `tools/gpu_run.sh
# probe` writes it) only packages of libraries the GPU machine lacks travel. Before it finishes, the script checks
# that refray renders here from the bundle's libraries alone.
#
# Usage: bash tools/gpu_bundle.sh [--build-dir DIR] [--no-build] [--target-ldconfig FILE] [--max-mib N]
set -euo pipefail

root=$(cd "$(dirname "$0")/.." && pwd)
build_dir="$root/build/gpu-bundle"
do_build=1
target_ldconfig=""
max_mib=50
while [ $# -gt 0 ]; do
  case "$1" in
    --build-dir) build_dir=$(realpath "$2"); shift 2 ;;
    --no-build) do_build=0; shift ;;
    --target-ldconfig) target_ldconfig=$(realpath "$2"); shift 2 ;;
    --max-mib) max_mib="$2"; shift 2 ;;
    -h|--help) sed -n '2,20p' "$0"; exit 0 ;;
    *) echo "gpu_bundle.sh: unknown argument '$1' (see --help)" >&2; exit 2 ;;
  esac
done
bundle="$root/.gpu-bundle"

# 1. The release binary and the SPIR-V.
if [ "$do_build" = 1 ]; then
  export CMAKE_CXX_COMPILER_LAUNCHER=${CMAKE_CXX_COMPILER_LAUNCHER:-ccache} CMAKE_C_COMPILER_LAUNCHER=${CMAKE_C_COMPILER_LAUNCHER:-ccache}
  # For another machine's CPU: not -march=native (REFRAY_NATIVE_ARCH), in a build directory of its own.
  (cd "$root" && cmake --preset release -B "$build_dir" -DREFRAY_VULKAN=ON -DREFRAY_NATIVE_ARCH=OFF -DREFRAY_PGO=OFF >/dev/null &&
     cmake --build "$build_dir" -j2 --target refray refray_spirv)
fi
binary="$build_dir/tools/refray"
spirv="$build_dir/gpu/shaders"
[ -x "$binary" ] || { echo "gpu_bundle.sh: no $binary (build the release preset, or give --build-dir)" >&2; exit 1; }
[ -d "$spirv" ] || { echo "gpu_bundle.sh: no $spirv: this build has no Vulkan back end (REFRAY_VULKAN)" >&2; exit 1; }

rm -rf "$bundle"
mkdir -p "$bundle/debs" "$bundle/gl" "$bundle/shaders" "$bundle/stand-ins"
cp "$binary" "$bundle/refray"
strip "$bundle/refray"
(cd "$spirv" && find . -name '*.spv' -exec cp --parents {} "$bundle/shaders/" \;)

# 2. The libraries: those refray uses travel as their Debian packages; the format plug-ins OpenImageIO links but
#    refray never calls (ffmpeg, OpenCV, DCMTK, OpenVDB, ...: 120 MiB of packages) as generated stand-ins
#    (tools/gpu_bundle_libraries.py says which and why).
python3 "$root/tools/gpu_bundle_libraries.py" "$binary" "$bundle"
declare -A packages=()
while read -r soname path; do
  if [ -n "$target_ldconfig" ] && grep -q "^[[:space:]]*$soname " "$target_ldconfig"; then
    continue  # the GPU machine has this library
  fi
  # dpkg knows a file by the path its package installs (/lib or /usr/lib on a merged-/usr system).
  real=$(readlink -f "$path")
  pkg=""
  for candidate in "$real" "${real#/usr}" "/usr${real}" "$path"; do
    pkg=$(dpkg -S "$candidate" 2>/dev/null | head -1 | cut -d: -f1 || true)
    [ -n "$pkg" ] && break
  done
  [ -n "$pkg" ] || { echo "gpu_bundle.sh: no package owns $path ($soname)" >&2; exit 1; }
  packages[$pkg]=1
done < "$bundle/carried.txt"
(cd "$bundle/debs" && apt-get download "${!packages[@]}" 2>&1 | grep -v '^W: Download is performed unsandboxed' || true)
(cd "$bundle/gl" && apt-get download libvulkan1 libegl1 libglvnd0 libopengl0 libgl1 libglx0 libgles2 2>&1 \
   | grep -v '^W: Download is performed unsandboxed' || true)

# The check: refray runs from the packages and stand-ins alone, with no library of this machine but the C and C++
# runtimes (the dynamic loader's cache off), and writes a PNG and an EXR.
check=$(mktemp -d)
trap 'rm -rf "$check"' EXIT
mkdir -p "$check/root" "$check/lib" "$check/runtime"
for f in "$bundle"/debs/*.deb; do dpkg -x "$f" "$check/root"; done
find "$check/root" -name '*.so*' \( -type f -o -type l \) -exec ln -sf {} "$check/lib/" \;
cp "$bundle"/stand-ins/*.so* "$check/lib/"
for s in libc.so.6 libm.so.6 libdl.so.2 libpthread.so.0 librt.so.1 libstdc++.so.6 libgcc_s.so.1; do
  ln -sf "/lib/x86_64-linux-gnu/$s" "$check/runtime/$s"
done
isolated=(/lib64/ld-linux-x86-64.so.2 --inhibit-cache --library-path "$check/lib:$check/runtime" "$bundle/refray")
if ! "${isolated[@]}" render builtin --size 32x18 -o "$check/check.png" >/dev/null || \
   ! "${isolated[@]}" render "$root/scenes/d3d12-procedural-geometry.json" --size 32x18 -o "$check/check.exr" >/dev/null; then
  echo "gpu_bundle.sh: refray does not run from the bundle's libraries alone (above: what it lacked)" >&2
  exit 1
fi
echo "checked: refray renders from the bundle's libraries and stand-ins alone"

# 3. Manifest and size.
{
  echo "refray GPU bundle, $(date -u +%Y-%m-%dT%H:%M:%SZ), commit $(git -C "$root" rev-parse --short=12 HEAD)"
  echo "binary: $binary"
  echo "spirv modules: $(find "$bundle/shaders" -name '*.spv' | wc -l)"
  echo "target ldconfig: ${target_ldconfig:-none (every package of the closure)}"
  echo "stand-ins (stand-ins/): $(cd "$bundle/stand-ins" && ls | tr '\n' ' ')"
  echo "packages (debs/):"
  (cd "$bundle/debs" && ls -1 *.deb | sed 's/^/  /')
  echo "loader (gl/):"
  (cd "$bundle/gl" && ls -1 *.deb | sed 's/^/  /')
} > "$bundle/MANIFEST"
bytes=$(du -sb "$bundle" | cut -f1)
mib=$((bytes / 1048576))
echo "wrote $bundle: ${#packages[@]} packages, $(find "$bundle/shaders" -name '*.spv' | wc -l) SPIR-V modules, $mib MiB"
if [ "$mib" -ge "$max_mib" ]; then
  echo "gpu_bundle.sh: the bundle is $mib MiB, over the $max_mib MiB limit. Its largest packages:" >&2
  (cd "$bundle/debs" && ls -S -s --block-size=K *.deb | head -12 >&2)
  echo "Carry only what the GPU machine lacks: run 'bash tools/gpu_run.sh probe' there (it writes ldconfig.txt to" >&2
  echo "\$OUT), then 'bash tools/gpu_bundle.sh --no-build --target-ldconfig ldconfig.txt' here." >&2
  exit 1
fi
