#!/usr/bin/env bash
# README command 2 (and .ci/run): set up, build, run every test; then the unit tests again under
# AddressSanitizer + UndefinedBehaviorSanitizer (clang) and a short run of every fuzzer.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
jobs=$(nproc)
"$root/scripts/setup.sh"

echo "== Release build and all tests"
# Explicit ON: the demo shares this build tree and turns tests off in it. With MPI: the mpirun tests
# (tests/distributed) run in this pass; the sanitizer build below stays without it.
"$root/scripts/build.sh" "$root/build" -DCADCLASH_BUILD_TESTS=ON -DCADCLASH_BUILD_BENCH=ON -DCADCLASH_BUILD_EXAMPLES=ON \
  -DCADCLASH_BUILD_PYTHON=ON -DCADCLASH_WITH_MPI=ON
ctest --test-dir "$root/build" --output-on-failure --no-tests=error -j "$jobs"

if [ "${CADCLASH_SKIP_SANITIZERS:-0}" != 1 ]; then
  echo "== clang ASan+UBSan build: the tests again, then a fuzz smoke run"
  # One clang tree serves the sanitizer tests and the libFuzzer targets (docs/fuzzing.md). -O1 with
  # asserts on (no NDEBUG) and line tables only: a short build, tests fast enough, readable traces.
  "$root/scripts/build.sh" "$root/build-sanitize" -DCMAKE_CXX_COMPILER=clang++-14 \
    -DCMAKE_BUILD_TYPE=RelWithDebInfo "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O1 -gline-tables-only" \
    -DCADCLASH_SANITIZE=address,undefined -DCADCLASH_BUILD_FUZZERS=ON -DCADCLASH_BUILD_TESTS=ON \
    -DCADCLASH_BUILD_BENCH=OFF -DCADCLASH_BUILD_EXAMPLES=OFF
  # OCCT allocates and frees through its own allocator; leaks it keeps for the process life are not ours.
  ASAN_OPTIONS=detect_leaks=0:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
    ctest --test-dir "$root/build-sanitize" --output-on-failure --no-tests=error -j "$jobs" -LE slow
  # (The exact-truth scenes of tests/collide/test_certified_truth.cpp run here in a reduced form: the
  # tighter tolerance and the certified mode, one distance per moved variant, 4 copies instead of 50;
  # about 35 s in one process at -O1 with ASan. The Release pass above runs them whole.)
  "$root/scripts/fuzz.sh" "$root/build-sanitize" obj off stl step iges triangles
fi
