#!/usr/bin/env bash
# Runs refray from .gpu-bundle/ (tools/gpu_bundle.sh) on the GPU machine, from the repository root.
#
#   bash tools/gpu_run.sh probe                 writes ldconfig.txt and ldd.txt to $OUT (or .) and prints what
#                                               refray lacks there: the input of gpu_bundle.sh --target-ldconfig
#   bash tools/gpu_run.sh render SCENE ARGS...  refray render SCENE --device vulkan ARGS...
#   bash tools/gpu_run.sh ARGS...               refray ARGS... (any subcommand)
#
# It installs the Vulkan loader and the glvnd set into / (dpkg -x; as the device README says), unpacks the
# library packages into .gpu-bundle/unpacked and links into .gpu-bundle/lib (never into /) each library and stand-in the
# machine lacks, puts that folder on LD_LIBRARY_PATH, prints the libraries refray still lacks, and points refray at
# the bundle's SPIR-V. docs/vulkan-backend.md, "Running on the GPU
# machine".
set -uo pipefail

bundle="$(pwd)/.gpu-bundle"
[ -x "$bundle/refray" ] || { echo "gpu_run.sh: no $bundle/refray; run tools/gpu_bundle.sh first, from the repository root" >&2; exit 2; }

# The loader, into / (with libvulkan1 alone vkCreateInstance fails with VK_ERROR_INCOMPATIBLE_DRIVER).
if ! ldconfig -p | grep 'libvulkan.so.1 ' >/dev/null; then
  for f in "$bundle"/gl/*.deb; do dpkg -x "$f" /; done
  ldconfig
fi
if [ -f /usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json ] && [ -z "${VK_DRIVER_FILES:-}" ] && \
   ! ls /usr/share/vulkan/icd.d/nvidia_icd.json /etc/vulkan/icd.d/nvidia_icd.json >/dev/null 2>&1; then
  export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
  export VK_ICD_FILENAMES=$VK_DRIVER_FILES  # the name loaders before 1.3.207 read
  export __EGL_VENDOR_LIBRARY_FILENAMES=/usr/local/nvidia/share/glvnd/egl_vendor.d/10_nvidia.json
fi

# The library packages, into the bundle's private folder; only libraries the machine lacks are linked into lib/, so
# the system's own copies (same soname) win.
if [ ! -d "$bundle/lib" ]; then
  mkdir -p "$bundle/unpacked" "$bundle/lib"
  system_libraries=$(ldconfig -p)  # (grep -q on a pipe from ldconfig would fail under pipefail)
  for f in "$bundle"/debs/*.deb; do dpkg -x "$f" "$bundle/unpacked"; done
  while read -r file; do
    name=$(basename "$file")
    if ! grep -q "^[[:space:]]*$name " <<<"$system_libraries"; then ln -sf "$file" "$bundle/lib/$name"; fi
  done < <(find "$bundle/unpacked" -name '*.so.*' \( -type f -o -type l \))
  # Stand-ins of the format libraries OpenImageIO links but refray never calls (tools/gpu_bundle_libraries.py).
  for standin in "$bundle"/stand-ins/*.so*; do
    name=$(basename "$standin")
    if ! grep -q "^[[:space:]]*$name " <<<"$system_libraries"; then ln -sf "$standin" "$bundle/lib/$name"; fi
  done
fi
export LD_LIBRARY_PATH="$bundle/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
export REFRAY_SPIRV_DIR="${REFRAY_SPIRV_DIR:-$bundle/shaders}"

missing=$(ldd "$bundle/refray" | grep 'not found')
if [ -n "$missing" ]; then
  echo "gpu_run.sh: refray still lacks these libraries (carry their packages: gpu_bundle.sh --target-ldconfig):" >&2
  echo "$missing" >&2
fi

case "${1:-}" in
  probe)
    out="${OUT:-.}"
    ldconfig -p > "$out/ldconfig.txt"
    ldd "$bundle/refray" > "$out/ldd.txt" 2>&1
    echo "wrote $out/ldconfig.txt and $out/ldd.txt"
    [ -z "$missing" ] && echo "refray finds every library it needs"
    command -v nvidia-smi >/dev/null && nvidia-smi --query-gpu=name,driver_version --format=csv,noheader
    exit 0 ;;
  render)
    shift
    exec "$bundle/refray" render "$@" --device vulkan ;;
  "")
    echo "usage: bash tools/gpu_run.sh probe | render SCENE [ARGS...] | ARGS..." >&2; exit 2 ;;
  *)
    exec "$bundle/refray" "$@" ;;
esac
