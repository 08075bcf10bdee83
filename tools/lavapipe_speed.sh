#!/usr/bin/env bash
# refray's emulator against Mesa's lavapipe (a CPU Vulkan driver, not a GPU) on the same machine, the same threads,
# in one run: every golden setting of tests/golden/goldens.json (scene, camera, time) at SIZE (default 1280x720),
# each rendered REPEATS times (default 3) by `refray render` (the emulator) and by `refray render --device vulkan
# --vulkan-device llvmpipe` (refray's Vulkan back end and GLSL ports on lavapipe), alternating. Per setting it writes
# the median trace time (refray: DispatchRays; lavapipe: vkCmdTraceRaysKHR by its timestamps, as `render` prints
# it) and the median whole-process time (loading, building, lavapipe's shader compilation, writing), and their
# ratios, as a Markdown table in build/lavapipe-speed/table.md and on stdout (docs/performance.md).
#   bash tools/lavapipe_speed.sh [--threads N] [--size WxH] [--repeats N] [--refray PATH]
# Needs a built refray (default build/release/tools/refray, else build/ci/tools/refray) and lavapipe
# (bash tools/setup.sh). Run it on a quiet machine: about 3 minutes on 2 cores.
set -euo pipefail
cd "$(dirname "$0")/.."
threads=2 size=1280x720 repeats=3 refray=""
while [ $# -gt 0 ]; do
  case $1 in
    --threads) threads=$2; shift 2 ;;
    --size) size=$2; shift 2 ;;
    --repeats) repeats=$2; shift 2 ;;
    --refray) refray=$2; shift 2 ;;
    -h|--help) sed -n '2,12p' "$0"; exit 0 ;;
    *) echo "lavapipe_speed: unknown argument '$1' (--threads N, --size WxH, --repeats N, --refray PATH)" >&2; exit 2 ;;
  esac
done
if [ -z "$refray" ]; then
  for candidate in build/release/tools/refray build/ci/tools/refray; do
    if [ -x "$candidate" ]; then refray=$candidate; break; fi
  done
fi
[ -n "$refray" ] && [ -x "$refray" ] || { echo "lavapipe_speed: no refray binary: build one (bash tools/refray.sh --help)" >&2; exit 1; }
if ! "$refray" devices 2>/dev/null | grep -q llvmpipe; then
  echo "lavapipe_speed: Mesa's lavapipe is missing; install it with: bash tools/setup.sh (as root)" >&2
  exit 1
fi
work=build/lavapipe-speed
mkdir -p "$work"
out=$work/table.md
export LP_NUM_THREADS=$threads  # llvmpipe's rasterizer/compute threads: the same count as refray's

# Every golden setting: NAME SCENE CAMERA TIME.
mapfile -t settings < <(python3 tools/gpu_crosscheck.py settings .)

# run_once DEVICE NAME SCENE CAMERA TIME: sets $trace (the image's render_seconds: refray's DispatchRays wall time,
# or on lavapipe the vkCmdTraceRaysKHR time from its timestamps) and $process (the whole command's wall time).
run_once() {
  local device=$1 name=$2 scene=$3 camera=$4 time=$5 extra=() log start end image
  [ "$device" = lavapipe ] && extra=(--device vulkan --vulkan-device llvmpipe)
  log=$work/$name.$device.log
  image=$work/$name.$device.exr
  start=$(date +%s.%N)
  if ! "$refray" render "$scene" --camera "$camera" --time "$time" --size "$size" --threads "$threads" "${extra[@]}" \
       -o "$image" > "$log" 2>&1; then
    echo "lavapipe_speed: $device failed on $name:" >&2; cat "$log" >&2; exit 1
  fi
  end=$(date +%s.%N)
  trace=$(python3 tools/gpu_crosscheck.py metadata "$image" | python3 -c 'import json,sys; print(json.load(sys.stdin)["render_seconds"])')
  process=$(awk -v a="$start" -v b="$end" 'BEGIN {printf "%.3f", b - a}')
}
median() { sort -g | awk '{a[NR]=$1} END {print (NR % 2) ? a[(NR + 1) / 2] : (a[NR / 2] + a[NR / 2 + 1]) / 2}'; }

device_line=$("$refray" devices --json | python3 -c '
import json, sys
for d in json.load(sys.stdin)["devices"]:
    if "llvmpipe" in d["driver"]:
        print(d["name"] + ", " + d["driverInfo"])')
{
  echo "### refray against Mesa's lavapipe ($size, $threads threads, median of $repeats alternating runs)"
  echo
  echo "lavapipe is a CPU Vulkan driver, not a GPU: \`$device_line\`. Trace: refray's DispatchRays (wall time) and"
  echo "lavapipe's vkCmdTraceRaysKHR (its timestamps); process: the whole \`refray render\` command."
  echo "Measured $(date -u +%Y-%m-%d) on $(nproc) cores ($(grep -m1 '^model name' /proc/cpuinfo | cut -d: -f2- | sed 's/^ *//'), load average $(cut -d' ' -f1-3 /proc/loadavg) at the start),"
  echo "refray $("$refray" --version | awk '{print $NF}'), by \`bash tools/lavapipe_speed.sh\`."
  echo
  echo "| setting | refray trace | lavapipe trace | refray / lavapipe | refray process | lavapipe process | refray / lavapipe |"
  echo "|---|---|---|---|---|---|---|"
} > "$out"
for line in "${settings[@]}"; do
  read -r name scene camera time <<< "$line"
  cpu_trace=() cpu_process=() lvp_trace=() lvp_process=()
  for r in $(seq "$repeats"); do
    run_once cpu "$name" "$scene" "$camera" "$time"
    cpu_trace+=("$trace"); cpu_process+=("$process")
    run_once lavapipe "$name" "$scene" "$camera" "$time"
    lvp_trace+=("$trace"); lvp_process+=("$process")
    echo "  $name run $r: refray ${cpu_trace[-1]} s (process ${cpu_process[-1]} s), lavapipe ${lvp_trace[-1]} s (process ${lvp_process[-1]} s)" >&2
  done
  ct=$(printf '%s\n' "${cpu_trace[@]}" | median); cp=$(printf '%s\n' "${cpu_process[@]}" | median)
  lt=$(printf '%s\n' "${lvp_trace[@]}" | median); lp=$(printf '%s\n' "${lvp_process[@]}" | median)
  printf '| %s, t = %s | %.3f s | %.3f s | %.2f | %.2f s | %.2f s | %.2f |\n' "$name" "$time" "$ct" "$lt" \
    "$(awk -v a="$ct" -v b="$lt" 'BEGIN {print a / b}')" "$cp" "$lp" "$(awk -v a="$cp" -v b="$lp" 'BEGIN {print a / b}')" >> "$out"
done
cat "$out"
