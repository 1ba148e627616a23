#!/usr/bin/env bash
# README command 1: set up, build (Release) and run the main job on a bundled real assembly.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
"$root/scripts/setup.sh"
echo "demo: building cadclash (Release; a few minutes the first time)" >&2
"$root/scripts/build.sh" "$root/build" -DCADCLASH_BUILD_TESTS=OFF -DCADCLASH_BUILD_BENCH=OFF -DCADCLASH_BUILD_EXAMPLES=OFF >/dev/null
exec "$root/build/tools/cadclash" check "$root/data/external/as1-tu-203.stp" "$@"
