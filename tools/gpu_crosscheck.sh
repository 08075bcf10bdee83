#!/usr/bin/env bash
# The GPU cross-check (docs/gpu-crosscheck.md): renders every golden's settings and the index maps on a Vulkan
# ray-tracing GPU, and brings the result into tests/gpu-renders/.
#
#   On the GPU machine, from the repository root, with .gpu-bundle/ (tools/gpu_bundle.sh) beside it:
#     bash tools/gpu_crosscheck.sh [OUTDIR]       (default $OUT, else .gpu-crosscheck)
#   renders, through tools/gpu_run.sh:
#     images/NAME.exr           every golden of tests/golden/goldens.json at its own settings (scene, camera, time,
#                               size, precision)
#     images/NAME.stats.exr     every statistical golden (the path tracer) re-rendered as a statistics image
#                               (--spp, --batches of the golden, seeds from 100: not the golden's)
#     maps/NAME.KIND.exr        the index maps record, instance, geometry, primitive, hitgroup (exact values, -1 for a miss:
#                               refray render --aov KIND -o FILE.exr) of every golden's setting at the golden size,
#                               and of every lesson in scenes/lessons/ whose render is defined (its camera)
#     speed.tsv                 every golden setting at 1280x720, 3 times: render_seconds (the GPU's trace time)
#                               and the wall time of the whole refray process
#     plan.tsv, commands.txt, log.txt, provenance.json (GPU, driver, Vulkan API, date, refray commit, commands)
#   and packs them into ONE file, OUTDIR/gpu-crosscheck.tar (a device call returns at most 8 files), with a copy of
#   log.txt beside it. REFRAY_CROSSCHECK_RENDER replaces `bash tools/gpu_run.sh render` (e.g. with
#   "build/ci/tools/refray render" for a dry run of the script on the CPU).
#
#   Here, after the device call:
#     bash tools/gpu_crosscheck.sh --import TARBALL [--dest tests/gpu-renders]
#   unpacks it into tests/gpu-renders/ (replacing the previous round) and writes its README.md.
set -euo pipefail

root=$(cd "$(dirname "$0")/.." && pwd)
size=320x180

if [ "${1:-}" = "--import" ]; then
  tarball=$(realpath "${2:?usage: gpu_crosscheck.sh --import TARBALL [--dest DIR]}")
  dest="$root/tests/gpu-renders"
  [ "${3:-}" = "--dest" ] && dest=$(realpath -m "${4:?--dest needs a folder}")
  work=$(mktemp -d)
  trap 'rm -rf "$work"' EXIT
  tar -xf "$tarball" -C "$work"
  src="$work/gpu-crosscheck"
  [ -f "$src/provenance.json" ] || { echo "gpu_crosscheck.sh: $tarball holds no gpu-crosscheck/provenance.json" >&2; exit 1; }
  mkdir -p "$dest"
  rm -rf "$dest/images" "$dest/maps"
  cp -r "$src/images" "$src/maps" "$src/provenance.json" "$dest/"
  for f in speed.tsv log.txt; do [ -f "$src/$f" ] && cp "$src/$f" "$dest/"; done
  python3 - "$dest" <<'EOF'
import json, sys
dest = sys.argv[1]
p = json.load(open(dest + "/provenance.json"))
images = [r for r in p["renders"] if r["what"] == "image" and r["rendered"]]
stats = [r for r in p["renders"] if r["what"] == "stats" and r["rendered"]]
maps = [r for r in p["renders"] if r["what"] == "map" and r["rendered"]]
missing = [r["file"] for r in p["renders"] if not r["rendered"]]
open(dest + "/README.md", "w").write(f"""# Renders made on a GPU (not by refray's CPU emulator)

These files come from **{p['gpu']}** (driver {p['gpuDriver']}, Vulkan API {p['vulkanAPI']}), rendered on
{p['date']} by refray {p['refrayVersion']} ({p['refrayCommit']}) with `refray render --device vulkan`
(docs/vulkan-backend.md), by `tools/gpu_crosscheck.sh` and imported with `tools/gpu_crosscheck.sh --import`.
They change only when a new GPU round is imported, never when the goldens change: the CTests
`GpuRenders.*` (tests/gpu-renders/gpu_renders_test.cpp) then tell whether refray still agrees with the hardware.

- `images/NAME.exr` ({len(images)}): each golden of tests/golden/goldens.json at its own settings, as the GPU
  rendered it (float RGBA). Checked against the golden with its order mask, within the per-scene bound of
  docs/gpu-crosscheck.md.
- `images/NAME.stats.exr` ({len(stats)}): each statistical golden's path-traced scene as the GPU rendered it, a
  statistics image (`--spp`, `--batches` of the golden, seeds from 100), judged with `refray compare --statistical`.
- `maps/NAME.KIND.exr` ({len(maps)}): the index maps (record, instance, geometry, primitive, hitgroup) of each pixel's primary
  ray as the GPU's AOV dispatch reported them: R = G = B = the index, -1 for a miss, exact in float32. Checked
  to equal refray's CPU maps of the same settings outside order-dependent pixels.
- `provenance.json`: the GPU, driver, Vulkan API, date, refray commit, the command lines, every render's settings,
  and the GPU's frame times at 1280x720 (`speed`, also `speed.tsv`).
- `log.txt`: the device call's output.
""" + (f"\nNot rendered on the GPU (see log.txt): {', '.join(missing)}\n" if missing else ""))
EOF
  echo "imported $(ls "$dest"/images | wc -l) images and $(ls "$dest"/maps | wc -l) maps into $dest"
  exit 0
fi

out="${1:-${OUT:-$root/.gpu-crosscheck}}"
mkdir -p "$out"
out=$(realpath "$out")
work=$(mktemp -d)  # not under $OUT: only the tar and the log come back
dir="$work/gpu-crosscheck"
mkdir -p "$dir/images" "$dir/maps"
read -r -a render <<<"${REFRAY_CROSSCHECK_RENDER:-bash tools/gpu_run.sh render}"
cd "$root"
exec > >(tee "$dir/log.txt") 2>&1
start=$(date +%s)
python3 tools/gpu_crosscheck.py plan "$root" "$size" > "$dir/plan.tsv"
: > "$dir/commands.txt"
: > "$dir/speed.tsv"
failures=0

# One refray call on the GPU; its command line goes to commands.txt. A scene that traces inline (RayQuery) on a
# device without VK_KHR_ray_query (the lent H100) is refused by refray with exit 2 and that extension named: it is
# skipped, not a failure (docs/vulkan-backend.md, "Ray queries and compute dispatch"; lavapipe checks those scenes).
skipped=0
gpu_render() {
  local line="${render[*]} $*"
  echo "${line//$work\//}" >> "$dir/commands.txt"
  if ! "${render[@]}" "$@" > "$dir/last.txt" 2>&1; then
    if grep -q "does not offer VK_KHR_ray_query" "$dir/last.txt"; then
      skipped=$((skipped + 1)); echo "SKIPPED (the device has no ray queries): $*"
      return 1
    fi
    failures=$((failures + 1)); echo "FAILED: $*"; cat "$dir/last.txt"
    return 1
  fi
}

while IFS=$'\t' read -r what name scene camera time wh precision aov output extra; do
  args=("$scene" --size "$wh")
  [ "$camera" != "-" ] && args+=(--camera "$camera")
  [ "$time" != "-" ] && args+=(--time "$time")
  case "$what" in
    image)
      echo "== image $name ($(( $(date +%s) - start )) s)"
      gpu_render "${args[@]}" --precision "$precision" -o "$dir/$output" || true ;;
    stats)
      echo "== statistics image $name $extra ($(( $(date +%s) - start )) s)"
      read -r -a more <<<"$extra"
      gpu_render "${args[@]}" "${more[@]}" -o "$dir/$output" || true ;;
    map)
      echo "== map $name $aov ($(( $(date +%s) - start )) s)"
      gpu_render "${args[@]}" --aov "$aov" -o "$dir/$output" || true ;;
    speed)
      for run in 1 2 3; do
        echo "== speed $name $wh run $run ($(( $(date +%s) - start )) s)"
        t0=$(date +%s.%N)
        gpu_render "${args[@]}" --precision "$precision" -o "$work/speed.exr" || continue
        t1=$(date +%s.%N)
        seconds=$(python3 tools/gpu_crosscheck.py metadata "$work/speed.exr" |
                  python3 -c 'import json,sys; print(json.load(sys.stdin)["render_seconds"])')
        printf '%s\t%s\t%s\t%s\t%s\n' "$name" "$run" "$wh" "$seconds" "$(python3 -c "print(round($t1 - $t0, 3))")" \
          >> "$dir/speed.tsv"
      done ;;
  esac
done < "$dir/plan.tsv"
rm -f "$dir/last.txt" "$work/speed.exr"

python3 tools/gpu_crosscheck.py provenance "$dir"
echo "gpu_crosscheck.sh: $(ls "$dir/images" | wc -l) images, $(ls "$dir/maps" | wc -l) maps, $failures failed, $skipped skipped (no ray queries), in $(( $(date +%s) - start )) s"
tar -cf "$out/gpu-crosscheck.tar" -C "$work" gpu-crosscheck
cp "$dir/log.txt" "$out/gpu-crosscheck-log.txt"
echo "wrote $out/gpu-crosscheck.tar ($(du -h "$out/gpu-crosscheck.tar" | cut -f1)); here: bash tools/gpu_crosscheck.sh --import gpu-crosscheck.tar"
