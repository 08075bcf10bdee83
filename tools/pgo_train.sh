#!/usr/bin/env bash
# The release build's profile (cmake/RefrayProfileGuided.cmake, docs/performance.md "Profile-guided and link-time
# optimisation"): builds the instrumented `pgo-train` preset's refray, renders the training set with it, and writes
# the profile to build/pgo-profile: GCC's counters and profile.stamp, their hash, which the release build reads (a
# new stamp makes it configure again; the first one compiles everything with the profile). The training set: every
# golden setting of tests/golden/goldens.json at 320x180, a double and a perturbed render (the envelope goldens'
# precisions) and the path tracer's two scenes, small, on one thread. About 20 s once built. The counters differ a
# little from run to run (hash tables keyed by addresses). ccache caches neither this build nor the release build
# (cmake/RefrayProfileGuided.cmake), so a fresh clone compiles both.
# It renders again only when the instrumented build's objects changed since the last training (their hash, less the
# objects that hold the commit (tools/version.h), which every commit rebuilds without changing what they run), or with
# --force.
#   bash tools/pgo_train.sh [--force]
# Exit status: 0 (a profile is there), 1 (a build or a training render failed: the message says which), 2 (usage).
set -euo pipefail
cd "$(dirname "$0")/.."
force=0
case "${1:-}" in
  "") ;;
  --force) force=1 ;;
  -h|--help) sed -n '2,14p' "$0"; exit 0 ;;
  *) echo "pgo_train: unknown argument '$1' (--force)" >&2; exit 2 ;;
esac
profile=build/pgo-profile
stamp=$profile/profile.stamp
objects_hash=$profile/objects.sha256
binary=build/pgo-train/tools/refray

# The hash of the instrumented build's objects, less the ones that include the generated tools/version.h (ninja's
# record of each object's headers says which).
objects_fingerprint() {
  local versioned
  versioned=$(ninja -C build/pgo-train -t deps | awk '/^[^ ].*: #deps/ {obj = $1; sub(/:$/, "", obj)}
                                                      /generated\/tools\/version\.h/ {print obj}' | sort -u)
  (cd build/pgo-train && find . -name '*.o' -type f | sed 's|^\./||' | LC_ALL=C sort |
     grep -vxF -f <(printf '%s\n' "$versioned" | grep .) | xargs sha256sum | sha256sum | cut -c1-16)
}

if [ ! -f build/pgo-train/build.ninja ]; then
  echo "pgo_train: configuring build/pgo-train (the instrumented build)" >&2
  cmake --preset pgo-train >&2
fi
echo "pgo_train: building the instrumented refray" >&2
cmake --build --preset pgo-train -j "$(nproc)" >&2
fingerprint=$(objects_fingerprint)
if [ "$force" = 0 ] && [ -f "$stamp" ] && [ "$(cat "$objects_hash" 2>/dev/null)" = "$fingerprint" ]; then
  echo "pgo_train: the profile is up to date ($(cat "$stamp"); the instrumented objects did not change)" >&2
  exit 0
fi

# The counters accumulate over runs: a new profile starts from none. The stamp goes last, so a failed training leaves
# no stamp (the release build then builds without a profile) rather than a partial profile under a stamp.
rm -rf "$profile"
mkdir -p "$profile"
work=build/pgo-train/renders
mkdir -p "$work"
mapfile -t training < <(python3 tools/gpu_crosscheck.py settings . |
                         awk '{print $1, $2, "--camera", $3, "--time", $4, "--size 320x180"}')
training+=(
  "d3d12.double scenes/d3d12-procedural-geometry.json --precision double --size 160x90"
  "d3d12.perturbed scenes/d3d12-procedural-geometry.json --perturb 1 --size 160x90"
  "cornell-box scenes/cornell-box.json --size 96x96"
  "textured-room scenes/textured-room.json --size 96x96"
)
start=$SECONDS
for line in "${training[@]}"; do
  read -r name args <<< "$line"
  echo "pgo_train: rendering $name" >&2
  # shellcheck disable=SC2086  # the arguments are words
  if ! "$binary" render $args --threads 1 -o "$work/$name.exr" > "$work/$name.log" 2>&1; then
    echo "pgo_train: the training render $name failed (refray render $args):" >&2
    cat "$work/$name.log" >&2
    exit 1
  fi
done
id=$(cd "$profile" && find . -name '*.gcda' -type f | LC_ALL=C sort | xargs sha256sum | sha256sum | cut -c1-16)
echo "$fingerprint" > "$objects_hash"
echo "$id" > "$stamp"
echo "pgo_train: profile $id in $profile ($(find "$profile" -name '*.gcda' | wc -l) files, $((SECONDS - start)) s of training)" >&2
