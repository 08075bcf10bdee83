#!/usr/bin/env bash
# Measures what docs/performance.md reports, on this machine, and writes the tables to build/perf-report/tables.md:
#   1. each effect's cost on both reference scenes (time with / without, median of alternating runs);
#   2. a scene with shadows switched off against a build whose shaders have no shadow call sites
#      (REFRAY_WITHOUT_SHADOW_MACHINERY), in time and in instructions (callgrind);
#   3. the traversal shortcuts' gain (--no-shortcuts against the default);
#   4. 1 -> 2 thread scaling and rays/s at 1280x720;
#   5. a callgrind profile of the slowest reference scene (its top functions by exclusive cost).
# The raw-Embree comparison is a Google Benchmark: build/release/tests/benchmarks/refray_reference_overhead_bench.
# Needs the release preset (bash tools/refray.sh builds it); builds build/perf-without-shadows itself. Run it on a
# quiet machine: about 15 minutes on 2 cores. Usage: bash tools/make_performance_report.sh [REPEATS]
set -euo pipefail
cd "$(dirname "$0")/.."
repeats="${1:-5}"
refray=build/release/tools/refray
[ -x "$refray" ] || { echo "make_performance_report: build the release preset first (bash tools/refray.sh --help)" >&2; exit 1; }
work=build/perf-report
rm -rf "$work"
mkdir -p "$work"
out="$work/tables.md"
: > "$out"

echo "== building the release preset without shadow call sites (build/perf-without-shadows)"
cmake --preset release -B build/perf-without-shadows -DREFRAY_WITHOUT_SHADOW_MACHINERY=ON -DREFRAY_BUILD_TESTS=OFF \
  -DREFRAY_BUILD_BENCHMARKS=OFF > /dev/null
cmake --build build/perf-without-shadows --target refray -j"$(nproc)" > /dev/null
noshadow=build/perf-without-shadows/tools/refray

d3d12=scenes/d3d12-procedural-geometry.json
proceduray=scenes/proceduray-mandel-julia-pac.json

# A copy of a scene file with an "effects" block (inserted after its "layout" line).
with_effects() {  # SCENE BLOCK OUT
  sed "s|^  \"layout\": \"auto\",|  \"layout\": \"auto\",\n  \"effects\": $2,|" "$1" > "$3"
  grep -q '"effects"' "$3" || { echo "make_performance_report: could not add an effects block to $1" >&2; exit 1; }
}

# seconds BINARY SCENE SIZE THREADS [ARGS...]: the dispatch's wall time (stats JSON, stage clocks off).
seconds() {
  local bin=$1 scene=$2 size=$3 threads=$4
  shift 4
  "$bin" render "$scene" --size "$size" --threads "$threads" --stats-json "$work/s.json" --no-stage-times \
    -o "$work/image.exr" "$@" > /dev/null
  sed -n 's/.*"wallSeconds": \([0-9.eE+-]*\).*/\1/p' "$work/s.json" | head -1
}
json_number() {  # KEY FILE
  sed -n "s/.*\"$1\": \([0-9.eE+-]*\).*/\1/p" "$2" | head -1
}
median() { sort -g | awk '{a[NR]=$1} END {print (NR % 2) ? a[(NR + 1) / 2] : (a[NR / 2] + a[NR / 2 + 1]) / 2}'; }

# compare LABEL SIZE THREADS "BIN SCENE ARGS" "BIN SCENE ARGS": medians of alternating runs and their ratio.
compare() {
  local label=$1 size=$2 threads=$3 a=$4 b=$5 ta=() tb=()
  for _ in $(seq "$repeats"); do
    read -r -a args <<< "$a"
    ta+=("$(seconds "${args[0]}" "${args[1]}" "$size" "$threads" "${args[@]:2}")")
    read -r -a args <<< "$b"
    tb+=("$(seconds "${args[0]}" "${args[1]}" "$size" "$threads" "${args[@]:2}")")
  done
  local ma mb
  ma=$(printf '%s\n' "${ta[@]}" | median)
  mb=$(printf '%s\n' "${tb[@]}" | median)
  printf '| %s | %.4f s | %.4f s | %.3f |\n' "$label" "$ma" "$mb" "$(awk -v a="$ma" -v b="$mb" 'BEGIN {print a / b}')" >> "$out"
  echo "   $label: $ma s / $mb s"
}

scene_file_for() { case $1 in d3d12) echo $d3d12 ;; proceduray) echo $proceduray ;; esac; }

for name in d3d12 proceduray; do
  scene=$(scene_file_for $name)
  with_effects "$scene" '{"shadows": false}' "$work/$name-no-shadows.json"
  with_effects "$scene" '{"reflectionDepth": 1}' "$work/$name-depth1.json"
  with_effects "$scene" '{"reflectionDepth": 2}' "$work/$name-depth2.json"
done

echo "== 1. effect costs (640x360, 2 threads, median of $repeats)"
{
  echo "### Effect costs (640x360, 2 threads, median of $repeats alternating runs)"
  echo
  echo "| scene: with / without | with | without | ratio |"
  echo "|---|---|---|---|"
} >> "$out"
for name in d3d12 proceduray; do
  scene=$(scene_file_for $name)
  compare "$name: shadows / shadows off" 640x360 2 "$refray $scene" "$refray $work/$name-no-shadows.json"
  compare "$name: reflections (depth 3) / depth 2" 640x360 2 "$refray $scene" "$refray $work/$name-depth2.json"
  compare "$name: depth 3 / depth 1 (no secondary rays)" 640x360 2 "$refray $scene" "$refray $work/$name-depth1.json"
  compare "$name: 4 spp / 1 spp" 640x360 2 "$refray $scene --spp 4" "$refray $scene"
  compare "$name: double / float" 640x360 2 "$refray $scene --precision double" "$refray $scene"
done

echo "== 2. shadows off against no shadow call sites"
{
  echo
  echo "### Shadows switched off against a build without shadow call sites (640x360, 2 threads)"
  echo
  echo "| scene | shadows off | no call sites | ratio |"
  echo "|---|---|---|---|"
} >> "$out"
for name in d3d12 proceduray; do
  compare "$name" 640x360 2 "$refray $work/$name-no-shadows.json" "$noshadow $work/$name-no-shadows.json"
done
{
  echo
  echo "| scene (160x90, 1 thread, callgrind) | instructions, shadows off | instructions, no call sites | ratio |"
  echo "|---|---|---|---|"
} >> "$out"
for name in d3d12 proceduray; do
  for bin in "$refray" "$noshadow"; do
    valgrind --tool=callgrind --callgrind-out-file="$work/cg.$name.$(basename "$(dirname "$(dirname "$bin")")")" \
      "$bin" render "$work/$name-no-shadows.json" --size 160x90 --threads 1 -o "$work/image.exr" > /dev/null 2>&1
  done
  ia=$(sed -n 's/^summary: //p' "$work/cg.$name.release")
  ib=$(sed -n 's/^summary: //p' "$work/cg.$name.perf-without-shadows")
  printf '| %s | %s | %s | %.4f |\n' "$name" "$ia" "$ib" "$(awk -v a="$ia" -v b="$ib" 'BEGIN {print a / b}')" >> "$out"
done

echo "== 3. traversal shortcuts"
{
  echo
  echo "### Traversal shortcuts (640x360, 2 threads): --no-shortcuts / default"
  echo
  echo "| scene | every candidate | shortcuts | ratio |"
  echo "|---|---|---|---|"
} >> "$out"
for name in d3d12 proceduray; do
  scene=$(scene_file_for $name)
  compare "$name" 640x360 2 "$refray $scene --no-shortcuts" "$refray $scene"
done

echo "== 4. threads and rays/s at 1280x720"
{
  echo
  echo "### 1280x720: thread scaling and rays/s (median of $repeats)"
  echo
  echo "| scene | 1 thread | 2 threads | speed-up | efficiency | rays | rays/s (2 threads) |"
  echo "|---|---|---|---|---|---|---|"
} >> "$out"
for name in d3d12 proceduray; do
  scene=$(scene_file_for $name)
  t1=() t2=()
  for _ in $(seq "$repeats"); do
    t1+=("$(seconds "$refray" "$scene" 1280x720 1)")
    t2+=("$(seconds "$refray" "$scene" 1280x720 2)")
  done
  m1=$(printf '%s\n' "${t1[@]}" | median)
  m2=$(printf '%s\n' "${t2[@]}" | median)
  rays=$(json_number raysTraced "$work/s.json")
  awk -v n="$name" -v a="$m1" -v b="$m2" -v r="$rays" \
    'BEGIN {printf "| %s | %.3f s | %.3f s | %.2fx | %.2f | %d | %.2f M |\n", n, a, b, a / b, a / (2 * b), r, r / b / 1e6}' >> "$out"
  echo "   $name: $m1 s / $m2 s"
done

echo "== 5. profile"
slowest=$d3d12
a=$(seconds "$refray" $d3d12 640x360 2)
b=$(seconds "$refray" $proceduray 640x360 2)
awk -v a="$a" -v b="$b" 'BEGIN {exit !(b > a)}' && slowest=$proceduray
# (awk, not head, ends the listings: head would close the pipe early, and pipefail would stop the script.)
# Only DispatchRays is collected: the program's start (the dynamic loader binding OpenImageIO's codecs) would
# otherwise dominate a small render.
valgrind --tool=callgrind --callgrind-out-file="$work/profile.cg" --toggle-collect='*Device::dispatchRays*' \
  "$refray" render "$slowest" --size 320x180 --threads 1 -o "$work/image.exr" > /dev/null 2>&1
{
  echo
  echo "### Profile: $(basename "$slowest" .json), 320x180, 1 thread (callgrind, DispatchRays only)"
  echo
  echo '```'
  callgrind_annotate --inclusive=no "$work/profile.cg" 2> /dev/null | sed -n '/^Ir/,$p' | awk 'NR <= 25' |
    sed 's|/work/[^ ]*/main/||g' | cut -c1-160
  echo
  echo "inclusive:"
  callgrind_annotate --inclusive=yes "$work/profile.cg" 2> /dev/null | sed -n '/^Ir/,$p' | awk 'NR <= 30' |
    sed 's|/work/[^ ]*/main/||g' | cut -c1-160
  echo '```'
} >> "$out"

echo "Machine: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //')" >> "$out"
echo "wrote $out"
