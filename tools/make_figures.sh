#!/usr/bin/env bash
# Renders the reference scenes and puts each beside the GPU image it should resemble (ours | theirs), for
# docs/reference-scenes.md. Needs a release build (tools/refray.sh builds one) and ../shared/reference-images.
# Usage: bash tools/make_figures.sh [REFERENCE_IMAGES_DIR]
set -euo pipefail
cd "$(dirname "$0")/.."
refs="${1:-../shared/reference-images}"
refray=build/release/tools/refray
out=docs/images
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
[ -x "$refray" ] || { echo "make_figures: build the release preset first (bash tools/refray.sh --help)" >&2; exit 1; }
mkdir -p "$out"

# side_by_side NAME OURS.png THEIRS.png: both scaled to 360 rows, ours on the left.
side_by_side() {
  oiiotool "$2" --resize 0x360 --ch R,G,B "$3" --resize 0x360 --ch R,G,B --mosaic:pad=8 2x1 -o "$out/$1.png"
}

proceduray=scenes/proceduray-mandel-julia-pac.json
for camera in overview julia mandelbulb; do
  "$refray" render "$proceduray" --camera "$camera" --size 640x360 -o "$tmp/proceduray-$camera.png"
done
"$refray" render scenes/d3d12-procedural-geometry.json --size 640x360 -o "$tmp/d3d12.png"

oiiotool "$refs/d3d12-procedural-geometry-screenshot.png" --cut 1280x720+0+30 -o "$tmp/d3d12-theirs.png"
side_by_side d3d12-procedural-geometry "$tmp/d3d12.png" "$tmp/d3d12-theirs.png"
side_by_side proceduray-overview "$tmp/proceduray-overview.png" "$refs/proceduray-scene.png"
side_by_side proceduray-julia "$tmp/proceduray-julia.png" "$refs/proceduray-julia1.png"
side_by_side proceduray-mandelbulb "$tmp/proceduray-mandelbulb.png" "$refs/proceduray-mandel1.png"


# The golden order masks of the D3D12 scene and the Proceduray Mandelbulb close-up, side by side.
oiiotool tests/golden/d3d12-procedural-geometry.default.order-mask.png \
  tests/golden/proceduray-mandel-julia-pac.mandelbulb.order-mask.png --mosaic:pad=8 2x1 -o "$out/order-masks.png"
echo "make_figures: wrote $(ls "$out" | wc -l) figures to $out"
