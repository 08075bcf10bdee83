#!/usr/bin/env bash
# Installs Mesa's lavapipe (mesa-vulkan-drivers) from Debian 12's bookworm-backports suite, where Mesa 25
# exposes VK_KHR_ray_tracing_pipeline, VK_KHR_acceleration_structure and VK_KHR_ray_query on any x86-64 CPU.
# lavapipe is a CPU driver, not a GPU. Idempotent: when a backports Mesa is installed it only says so.
#
# The suite is added in the machine's own apt sources format (deb822 .sources or one-line .list), with the
# mirror taken from the source that already serves 'bookworm' on this machine: no host is named here.
set -euo pipefail

want_major=25
installed=$(dpkg-query -W -f='${Status} ${Version}' mesa-vulkan-drivers 2>/dev/null || true)
if [[ "$installed" == "install ok installed "* ]]; then
  version=${installed##* }
  major=${version%%.*}; major=${major#*:}
  if [ "$major" -ge "$want_major" ] 2>/dev/null; then
    echo "setup: lavapipe present (mesa-vulkan-drivers $version)"
    exit 0
  fi
fi

if [ "$(id -u)" -ne 0 ]; then
  echo "setup: lavapipe (mesa-vulkan-drivers >= $want_major from bookworm-backports) is missing;" >&2
  echo "setup: run 'bash tools/setup.sh' as root to install it" >&2
  exit 1
fi

# Is bookworm-backports already among the machine's sources?
has_backports() {
  grep -rhsE '^[^#]*bookworm-backports' /etc/apt/sources.list /etc/apt/sources.list.d/*.list \
       /etc/apt/sources.list.d/*.sources >/dev/null 2>&1
}

if ! has_backports; then
  mirror=""
  format=""
  # deb822 files: a stanza whose Suites has 'bookworm' and whose URIs is Debian's main archive (not -security).
  for f in /etc/apt/sources.list.d/*.sources; do
    [ -f "$f" ] || continue
    mirror=$(awk '
      /^[[:space:]]*$/ { if (suite && uri && !sec) { print uri; exit } suite = 0; uri = ""; sec = 0; next }
      /^URIs:/ { uri = $2; if (uri ~ /security/) sec = 1 }
      /^Suites:/ { for (i = 2; i <= NF; i++) if ($i == "bookworm") suite = 1 }
      END { if (suite && uri && !sec) print uri }' "$f" | head -n1)
    if [ -n "$mirror" ]; then format=deb822; break; fi
  done
  if [ -z "$mirror" ]; then
    for f in /etc/apt/sources.list /etc/apt/sources.list.d/*.list; do
      [ -f "$f" ] || continue
      mirror=$(awk '$1 == "deb" { for (i = 2; i < NF; i++) if ($(i+1) == "bookworm" && $i !~ /security/) { print $i; exit } }' \
               "$f" | sed 's/^\[.*\]$//' | head -n1)
      if [ -n "$mirror" ]; then format=list; break; fi
    done
  fi
  if [ -z "$mirror" ]; then
    echo "setup: no apt source serves Debian 'bookworm' on this machine; add bookworm-backports by hand" >&2
    echo "setup: (see https://backports.debian.org/Instructions/) and run tools/setup.sh again" >&2
    exit 1
  fi
  if [ "$format" = deb822 ]; then
    cat > /etc/apt/sources.list.d/refray-bookworm-backports.sources <<SRC
# Added by refray's tools/setup.sh for Mesa's lavapipe (mesa-vulkan-drivers >= $want_major).
Types: deb
URIs: $mirror
Suites: bookworm-backports
Components: main
Signed-By: /usr/share/keyrings/debian-archive-keyring.gpg
SRC
  else
    echo "deb $mirror bookworm-backports main" > /etc/apt/sources.list.d/refray-bookworm-backports.list
  fi
  echo "setup: added bookworm-backports ($mirror) to the apt sources"
fi

echo "setup: installing lavapipe (mesa-vulkan-drivers from bookworm-backports)"
export DEBIAN_FRONTEND=noninteractive
apt-get update -qq
apt-get install -y -qq --no-install-recommends -t bookworm-backports mesa-vulkan-drivers
echo "setup: lavapipe installed (mesa-vulkan-drivers $(dpkg-query -W -f='${Version}' mesa-vulkan-drivers))"
