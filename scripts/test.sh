#!/usr/bin/env bash
# README command 2 (and .ci/run): set up, build, run every test; then the unit tests again under
# AddressSanitizer + UndefinedBehaviorSanitizer.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
jobs=$(nproc)
"$root/scripts/setup.sh"

echo "== Release build and all tests"
# Explicit ON: the demo shares this build tree and turns tests off in it.
"$root/scripts/build.sh" "$root/build" -DCADCLASH_BUILD_TESTS=ON -DCADCLASH_BUILD_BENCH=ON -DCADCLASH_BUILD_EXAMPLES=ON
ctest --test-dir "$root/build" --output-on-failure --no-tests=error -j "$jobs"

if [ "${CADCLASH_SKIP_SANITIZERS:-0}" != 1 ]; then
  echo "== ASan+UBSan build and the tests again"
  "$root/scripts/build.sh" "$root/build-asan" -DCMAKE_BUILD_TYPE=Debug -DCADCLASH_SANITIZE=address,undefined \
    -DCADCLASH_BUILD_BENCH=OFF -DCADCLASH_BUILD_EXAMPLES=OFF
  # OCCT allocates and frees through its own allocator; leaks it keeps for the process life are not ours.
  ASAN_OPTIONS=detect_leaks=0:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
    ctest --test-dir "$root/build-asan" --output-on-failure --no-tests=error -j "$jobs" -LE slow
fi
