#!/usr/bin/env bash
# Installs every Debian 12 package cadclash needs and unpacks the real CAD sample data into
# data/external/. Idempotent: a second run only checks, so it is fast when everything is there.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)

build_packages=(
  build-essential cmake ninja-build pkg-config
  libocct-foundation-dev libocct-modeling-data-dev libocct-modeling-algorithms-dev
  libocct-data-exchange-dev libocct-ocaf-dev libocct-visualization-dev
  libcgal-dev libgmp-dev libmpfr-dev
  libassimp-dev libeigen3-dev libboost-dev libtbb-dev
  libgtest-dev libgmock-dev libbenchmark-dev libfcl-dev
  nlohmann-json3-dev libcli11-dev libssl-dev
  libopenmpi-dev openmpi-bin
  clang-14 libomp-14-dev libclang-rt-14-dev
  pybind11-dev python3-pybind11 python3-numpy python3-pytest
  chromium gnuplot-nox
)
data_packages=(gmsh-doc occt-misc netgen-doc)

sudo_cmd=()
if [ "$(id -u)" != 0 ]; then sudo_cmd=(sudo); fi

missing=()
for p in "${build_packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "setup: installing ${missing[*]}" >&2
  "${sudo_cmd[@]}" apt-get update -qq
  DEBIAN_FRONTEND=noninteractive "${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

ext="$root/data/external"
stamp="$ext/.complete"
if [ ! -f "$stamp" ]; then
  echo "setup: fetching sample CAD data (${data_packages[*]}) into data/external" >&2
  work=$(mktemp -d)
  trap 'rm -rf "$work"' EXIT
  chmod 755 "$work"  # apt's sandbox user must be able to write the downloads here
  if [ ${#missing[@]} -eq 0 ]; then "${sudo_cmd[@]}" apt-get update -qq; fi
  (cd "$work" && apt-get download -qq "${data_packages[@]}" >/dev/null)
  for deb in "$work"/*.deb; do dpkg -x "$deb" "$work/x"; done
  mkdir -p "$ext"
  # Copy every CAD and mesh file, flattening the tree; gunzip the compressed ones.
  find "$work/x" -type f \( -iname '*.stp' -o -iname '*.step' -o -iname '*.igs' -o -iname '*.iges' \
       -o -iname '*.brep' -o -iname '*.rle' -o -iname '*.stl' -o -iname '*.stp.gz' -o -iname '*.step.gz' \
       -o -iname '*.igs.gz' -o -iname '*.iges.gz' -o -iname '*.brep.gz' -o -iname '*.stl.gz' \) -print0 |
    while IFS= read -r -d '' f; do
      name=$(basename "$f")
      case "$name" in
        *.gz) gunzip -c "$f" > "$ext/${name%.gz}" ;;
        *) cp "$f" "$ext/$name" ;;
      esac
    done
  touch "$stamp"
fi

# The HTML clash viewer (viewer/): three.js, esbuild and playwright-core from npm, pinned by
# viewer/package-lock.json; `npm ci` again whenever the lock file is newer than node_modules.
if ! command -v npm >/dev/null; then
  echo "setup: installing nodejs npm" >&2
  "${sudo_cmd[@]}" apt-get update -qq
  DEBIAN_FRONTEND=noninteractive "${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends nodejs npm >/dev/null
fi
viewer="$root/viewer"
if [ ! -f "$viewer/node_modules/.package-lock.json" ] ||
   [ "$viewer/package-lock.json" -nt "$viewer/node_modules/.package-lock.json" ]; then
  echo "setup: npm ci in viewer/" >&2
  (cd "$viewer" && npm ci --no-audit --no-fund --loglevel=error)
fi
