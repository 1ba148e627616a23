#!/usr/bin/env bash
# ThreadSanitizer run of the parallel collide tests and of the decision stage on real scenes:
#   scripts/tsan.sh [BUILD_DIR (default build-tsan)]
#
# Why clang: GCC's libgomp is not TSan-instrumented, so every OpenMP barrier shows up as a false race.
# clang -fopenmp links LLVM's libomp; its Archer tool (libarcher.so, OMPT) tells TSan about OpenMP's
# barriers, tasks and locks, so what TSan still reports is a real race in our code. Any report fails
# the run (halt_on_error=1, exitcode 66). Opt-in; not part of scripts/test.sh.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
dir=${1:-$root/build-tsan}
llvm=/usr/lib/llvm-14

if ! command -v clang++-14 >/dev/null 2>&1 || [ ! -f "$llvm/lib/libarcher.so" ]; then
  sudo_cmd=(); if [ "$(id -u)" != 0 ]; then sudo_cmd=(sudo); fi
  "${sudo_cmd[@]}" apt-get update -qq
  DEBIAN_FRONTEND=noninteractive "${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends \
    clang-14 libomp-14-dev >/dev/null
fi

generator=()
if command -v ninja >/dev/null 2>&1; then generator=(-G Ninja); fi
# Only collide's tests are built, with what test_certified_truth needs (tessellate, import and the
# test support library); tools/ is configured (tests/tools needs it) but never compiled.
cmake -S "$root" -B "$dir" "${generator[@]}" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_CXX_COMPILER=clang++-14 -DCADCLASH_SANITIZE=thread \
  -DCADCLASH_BUILD_TOOLS=ON -DCADCLASH_BUILD_BENCH=OFF -DCADCLASH_BUILD_EXAMPLES=OFF \
  -DCADCLASH_BUILD_TESTS=ON >/dev/null
# test_certified_truth: the decision stage on real B-rep scenes (its reduced form under a sanitizer),
# with OCCT's exact geometry queried from several threads.
targets=(test_collide test_collide_narrow_phase test_certified_truth)
cmake --build "$dir" --target "${targets[@]}" -j "${CADCLASH_JOBS:-$(nproc)}"

# The OpenMP runtime must be LLVM's, or Archer has nothing to hook into.
if ! ldd "$dir/tests/collide/test_collide_narrow_phase" | grep -q 'libomp\.so'; then
  echo "tsan.sh: test binary is not linked against libomp" >&2; exit 1
fi

export OMP_NUM_THREADS=${OMP_NUM_THREADS:-4}
export OMP_TOOL_LIBRARIES=$llvm/lib/libarcher.so
export ARCHER_OPTIONS=${ARCHER_OPTIONS:-verbose=1}
# ignore_noninstrumented_modules: libomp's own internals are not instrumented (Archer's advice).
export TSAN_OPTIONS="halt_on_error=1 exitcode=66 ignore_noninstrumented_modules=1 second_deadlock_stack=1 ${TSAN_OPTIONS:-}"
export LD_LIBRARY_PATH=$llvm/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}
for t in "${targets[@]}"; do
  echo "== $t under TSan (OMP_NUM_THREADS=$OMP_NUM_THREADS)"
  filter=${CADCLASH_TSAN_FILTER:-}
  # The truth scenes' own ground truth is serial OCCT work: the checks on threads are what TSan is for.
  if [ -z "$filter" ] && [ "$t" = test_certified_truth ]; then
    filter='CertifiedDeterminism.*:CertifiedTruth.As1AsRead:CertifiedTruth.Board:Invariance.*:OcctDistance.*'
  fi
  "$dir/tests/collide/$t" ${filter:+--gtest_filter="$filter"}
done
echo "tsan.sh: no data race reported"
