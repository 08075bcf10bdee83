#!/usr/bin/env bash
# One command from a fresh Debian 12 machine to a render: installs refray's packages
# (tools/setup.sh), makes the release build's profile (tools/pgo_train.sh), configures and builds the release
# preset when needed, then runs `refray` with the given arguments, e.g.
#   bash tools/refray.sh render scenes/proceduray-mandel-julia-pac.json -o proceduray.png
set -euo pipefail
cd "$(dirname "$0")/.."

bash tools/setup.sh >&2
# The release build is profile-guided (cmake/RefrayProfileGuided.cmake): its profile first, made again only when the
# instrumented build changed. REFRAY_PGO=0 skips it (the release build is then a plain -O3 build, slower to render).
pgo=USE
if [ "${REFRAY_PGO:-1}" = 0 ]; then pgo=OFF; else bash tools/pgo_train.sh; fi
if [ ! -f build/release/build.ninja ] || ! grep -qx "REFRAY_PGO:STRING=$pgo" build/release/CMakeCache.txt; then
  echo "refray.sh: configuring build/release (REFRAY_PGO=$pgo)" >&2
  cmake --preset release -DREFRAY_PGO="$pgo" >&2
fi
echo "refray.sh: building (first time: several minutes on 2 cores)" >&2
cmake --build build/release --target refray -j "$(nproc)" >&2
exec build/release/tools/refray "$@"
