#!/usr/bin/env bash
# Runs the accuracy sweeps of both reference scenes on this machine and writes docs/accuracy-vs-time.md with their
# plots (docs/images/accuracy/). Needs a release build (bash tools/refray.sh builds one). Takes about 6 minutes on
# 2 cores. Usage: bash tools/make_accuracy_report.sh [THREADS]
set -euo pipefail
cd "$(dirname "$0")/.."
threads="${1:-2}"
refray=build/release/tools/refray
[ -x "$refray" ] || { echo "make_accuracy_report: build the release preset first (bash tools/refray.sh --help)" >&2; exit 1; }
work=build/accuracy-sweeps
images=docs/images/accuracy
doc=docs/accuracy-vs-time.md
rm -rf "$work" "$images"
mkdir -p "$work" "$images"

common=(--size 320x180 --repeats 5 --threads "$threads" --golden-search
        --knob steps=0.125,0.25,0.5,2,4 --knob threshold=0.25,0.5,2,4,8 --knob normal-epsilon=0.1,0.5,2,10
        --knob recursion-depth=1,2,4,6 --knob precision=double --knob spp=4,9,16)

# sweep NAME SCENE [ARGS...]: one sweep into $work/NAME, its plots copied to $images/NAME.
sweep() {
  local name=$1 scene=$2
  shift 2
  echo "== $name"
  "$refray" sweep "$scene" "${common[@]}" "$@" -o "$work/$name"
  mkdir -p "$images/$name"
  cp "$work/$name"/plots/*.png "$images/$name/"
  cp "$work/$name/sweep.csv" "$images/$name/sweep.csv"
}

sweep proceduray scenes/proceduray-mandel-julia-pac.json \
  --knob mandelbulb-iterations=2,3,6,8 --knob julia-iterations=25,50,100,400
sweep proceduray-mandelbulb scenes/proceduray-mandel-julia-pac.json --camera mandelbulb \
  --knob mandelbulb-iterations=2,3,6,8
sweep d3d12 scenes/d3d12-procedural-geometry.json --knob metaball-steps=16,32,64,256,512

{
  cat docs/accuracy-vs-time.intro.md
  echo
  echo "Machine: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //'), $threads render threads;"
  echo "refray $("$refray" --version); generated $(date -u +%Y-%m-%d) by \`bash tools/make_accuracy_report.sh\`."
  for name in proceduray proceduray-mandelbulb d3d12; do
    echo
    # Demote the sweep's headings one level and point its images at the copies.
    sed -e 's/^## /### /' -e 's/^# /## /' -e "s|(plots/|(images/accuracy/$name/|g" "$work/$name/sweep.md"
    echo
    echo "Every run: [images/accuracy/$name/sweep.csv](images/accuracy/$name/sweep.csv)."
  done
} > "$doc"
echo "wrote $doc and $images"
