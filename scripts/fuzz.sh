#!/usr/bin/env bash
# Runs the libFuzzer targets of fuzz/: scripts/fuzz.sh [BUILD_DIR (default build-sanitize)] [TARGET...]
# TARGET is obj, off, stl, step, iges or triangles (default: all). docs/fuzzing.md has the details.
#
# The build tree must be configured with clang and -DCADCLASH_BUILD_FUZZERS=ON (scripts/test.sh's
# sanitizer tree is). Each target starts from its committed seeds (fuzz/corpus/<target>/) plus, at
# run time, the sample files of its format under data/external/ up to the target's input size
# limit; what it learns goes to BUILD_DIR/fuzz/<target>/corpus and is kept for the next run.
# Any crash, sanitizer report, broken contract, hang or memory blowup fails the run and prints the
# path of the input that caused it; replay it with BUILD_DIR/fuzz/fuzz_<target> THAT_FILE.
#
# Environment: CADCLASH_FUZZ_SECONDS per target (default 25), CADCLASH_FUZZ_PARALLEL targets at
# once (default 2), CADCLASH_FUZZ_TIMEOUT seconds one input may take (default 10),
# CADCLASH_FUZZ_RSS_MB memory limit per target (default 2048).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
dir=${1:-$root/build-sanitize}
if [ $# -gt 0 ]; then shift; fi
targets=("$@")
if [ ${#targets[@]} -eq 0 ]; then targets=(obj off stl step iges triangles); fi
seconds=${CADCLASH_FUZZ_SECONDS:-25}
parallel=${CADCLASH_FUZZ_PARALLEL:-2}
timeout=${CADCLASH_FUZZ_TIMEOUT:-10}
rss_mb=${CADCLASH_FUZZ_RSS_MB:-2048}

# Largest input libFuzzer makes per target, and the extensions of its data/external seeds. STEP
# files are large by nature; the mesh readers' interesting structure fits in a few kilobytes.
max_len() { case $1 in triangles) echo 512 ;; *) echo 65536 ;; esac; }
extensions() { case $1 in obj) echo obj ;; off) echo off ;; stl) echo stl ;; step) echo "stp step" ;; iges) echo "igs iges" ;; *) ;; esac; }

for t in "${targets[@]}"; do
  if [ ! -x "$dir/fuzz/fuzz_$t" ]; then
    echo "fuzz.sh: $dir/fuzz/fuzz_$t not built (configure with clang and -DCADCLASH_BUILD_FUZZERS=ON)" >&2
    exit 2
  fi
done

# OCCT keeps caches for the life of the process, which LeakSanitizer would report after every
# input; the suppressions name only OCCT and its allocator (see the file).
export LSAN_OPTIONS="suppressions=$root/fuzz/lsan.supp print_suppressions=0 ${LSAN_OPTIONS:-}"
export UBSAN_OPTIONS="print_stacktrace=1 halt_on_error=1 ${UBSAN_OPTIONS:-}"
export ASAN_OPTIONS="abort_on_error=1 ${ASAN_OPTIONS:-}"

run_one() {
  local t=$1 work="$dir/fuzz/$1" len
  len=$(max_len "$t")
  mkdir -p "$work/corpus" "$work/external" "$work/tmp"
  rm -f "$work"/crash-* "$work"/timeout-* "$work"/oom-* "$work"/leak-* "$work"/slow-unit-*
  # Real files no one here wrote: linked in at run time, never committed (data/external is ignored).
  find "$work/external" -type l -delete
  for ext in $(extensions "$t"); do
    find "$root/data/external" -maxdepth 1 -type f -iname "*.$ext" -size -"$((len / 1024 + 1))"k \
      -exec ln -sf {} "$work/external/" \; 2>/dev/null || true
  done
  echo "fuzz.sh: $t for ${seconds}s (log $work/log)"
  # The scratch files of a fuzzer that crashed stay in the build tree, not in /tmp.
  if TMPDIR="$work/tmp" "$dir/fuzz/fuzz_$t" "$work/corpus" "$root/fuzz/corpus/$t" "$work/external" \
       -max_total_time="$seconds" -timeout="$timeout" -rss_limit_mb="$rss_mb" -max_len="$len" \
       -artifact_prefix="$work/" -print_final_stats=1 >"$work/log" 2>&1; then
    echo "fuzz.sh: $t ok: $(grep -E '^stat::number_of_executed_units' "$work/log" | awk '{print $2}') inputs run"
    return 0
  fi
  echo "fuzz.sh: $t FAILED; the end of its log:" >&2
  tail -n 60 "$work/log" >&2
  for f in "$work"/crash-* "$work"/timeout-* "$work"/oom-* "$work"/leak-*; do
    [ -e "$f" ] && echo "fuzz.sh: $t failing input: $f (replay: $dir/fuzz/fuzz_$t $f)" >&2
  done
  return 1
}

# Two at a time by default: libFuzzer runs one process per target, and CI has two cores.
failed=0
running=0
for t in "${targets[@]}"; do
  if [ "$running" -ge "$parallel" ]; then
    wait -n || failed=1
    running=$((running - 1))
  fi
  run_one "$t" &
  running=$((running + 1))
done
while [ "$running" -gt 0 ]; do
  wait -n || failed=1
  running=$((running - 1))
done
if [ "$failed" != 0 ]; then echo "fuzz.sh: a fuzzer found a problem (see above)" >&2; exit 1; fi
echo "fuzz.sh: no problem found in ${#targets[@]} targets x ${seconds}s"
