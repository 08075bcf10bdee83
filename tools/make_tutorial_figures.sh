#!/usr/bin/env bash
# Renders the pictures of docs/tutorial-indexing.md: index maps of both reference scenes, each lesson beside the
# scene it breaks, and the interactive explain page as a browser shows it. Needs a release build
# (bash tools/refray.sh builds one), oiiotool and chromium (tools/setup.sh installs both).
# Usage: bash tools/make_tutorial_figures.sh
set -euo pipefail
cd "$(dirname "$0")/.."
refray=build/release/tools/refray
out=docs/images/tutorial
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
[ -x "$refray" ] || { echo "make_tutorial_figures: build the release preset first (bash tools/refray.sh --help)" >&2; exit 1; }
mkdir -p "$out"
proceduray=scenes/proceduray-mandel-julia-pac.json
d3d12=scenes/d3d12-procedural-geometry.json

# Index maps with their legends.
"$refray" render "$proceduray" --size 320x180 --aov record -o "$out/proceduray-record.png" >/dev/null
"$refray" render "$proceduray" --size 320x180 --aov depth -o "$out/proceduray-depth.png" >/dev/null
"$refray" render "$d3d12" --size 320x180 --aov record -o "$out/d3d12-record.png" >/dev/null

# pair NAME BASE LESSON [CAMERA]: the base scene | the lesson, 320x180 each; alpha dropped (a missing closest hit
# leaves alpha 0, which a viewer would show as transparent).
pair() {
  local camera=()
  [ $# -ge 4 ] && camera=(--camera "$4")
  "$refray" render "$2" --size 320x180 "${camera[@]}" -o "$tmp/base.png" >/dev/null
  "$refray" render "$3" --size 320x180 "${camera[@]}" -o "$tmp/lesson.png" >/dev/null
  oiiotool "$tmp/base.png" --ch R,G,B "$tmp/lesson.png" --ch R,G,B --mosaic:pad=8 2x1 -o "$out/$1.png"
}
pair lesson-contribution-off-by-one "$proceduray" scenes/lessons/contribution-off-by-one.json
pair lesson-mask-hides-an-instance "$proceduray" scenes/lessons/mask-hides-an-instance.json
pair lesson-multiplier-one "$d3d12" scenes/lessons/multiplier-one.json
"$refray" render scenes/lessons/multiplier-one.json --size 320x180 --aov record -o "$out/lesson-multiplier-one-record.png" >/dev/null

# The interactive page with pixel (112, 100) pinned, as headless Chromium draws it.
"$refray" explain "$proceduray" --size 320x180 --html "$tmp/explain.html" >/dev/null
chromium --headless --disable-gpu --no-sandbox --user-data-dir="$tmp/profile" --hide-scrollbars \
  --window-size=1700,720 --screenshot="$out/explain-page.png" "file://$tmp/explain.html#pixel=112,100" 2>/dev/null
echo "make_tutorial_figures: wrote $(ls "$out" | wc -l) figures to $out"
