#!/usr/bin/env bash
# What certification costs on real-part boards (docs/results.md, "Certified against --fast on
# real-part boards"; issue 42): the KiCad corpus boards (scripts/make_corpus.sh: components seated
# 0.05 mm above a board drilled for their pins) and the seated / sunk boards of
# scripts/uncertainty_bench.sh, each checked certified and --fast in one run, 2 threads: what each
# reports, which certificate decided the pairs the triangles left open, and the query and end-to-end
# times side by side (the median of BOARDS_BENCH_REPEATS runs each, default 5). The 174 MB board only
# with CADCLASH_BENCH_LARGE=1 (its import takes a minute).
# Writes a Markdown table on stdout.
#   bash scripts/boards_bench.sh [BUILD_DIR] [OUT_DIR] [UNCERTAINTY_DIR]
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-$root/build}
out=${2:-$root/out/boards_bench}
band=${3:-$root/out/uncertainty_bench}
cadclash=$build/tools/cadclash
corpus=$root/out/corpus
if [ ! -x "$cadclash" ] || [ ! -f "$corpus/board-5mb.step" ]; then
  echo "_No KiCad board corpus in this tree (bash scripts/make_corpus.sh), or cadclash not built._"
  exit 0
fi
mkdir -p "$out"
# name | file | options
# The pins stand 0.1 mm from their holes' rims (make_board_assembly's clearance): at tolerance 0.095
# with OCCT's tolerances alone every pin against the board's top and bottom faces is within the
# triangles' band; the holes' radii decide them (the analytic step; before it, finer triangles of
# the board near each pin).
runs=("board-5mb|$corpus/board-5mb.step|" "board-5mb-rims|$corpus/board-5mb.step|--tolerance 0.095 --uncertainty occt"
      "board-40mb|$corpus/board-40mb.step|")
if [ "${CADCLASH_BENCH_LARGE:-0}" = 1 ] && [ -f "$corpus/board-150mb.step" ]; then
  runs+=("board-150mb|$corpus/board-150mb.step|")
fi
if [ -f "$band/board-seated.step" ]; then
  runs+=("seated|$band/board-seated.step|" "seated-occt|$band/board-seated.step|--tolerance 0.04 --uncertainty occt")
fi
[ -f "$band/board-sunk.step" ] && runs+=("sunk|$band/board-sunk.step|")
repeats=${BOARDS_BENCH_REPEATS:-5}
rm -f "$out/runs.txt.new"
for r in "${runs[@]}"; do
  IFS='|' read -r name file options <<<"$r"
  # Each mode $repeats times, alternating, so both see the same machine; the run with the median
  # query time is the one shown (its report and counters are the same in every run).
  for i in $(seq 1 "$repeats"); do
    for mode in certified fast; do
      extra=()
      [ "$mode" = fast ] && extra=(--fast)
      # shellcheck disable=SC2086  # options are words
      "$cadclash" check "$file" $options --threads 2 -q "${extra[@]}" --json "$out/$name-$mode-$i.json" \
        >/dev/null 2>"$out/$name-$mode.err" || true
    done
  done
  printf '%s|%s|%s|%s\n' "$name" "$file" "$options" "$repeats" >>"$out/runs.txt.new"
done
mv "$out/runs.txt.new" "$out/runs.txt"
python3 - "$out" <<'PY'
import json, os, sys
out = sys.argv[1]
label = {"board-5mb": "corpus 5 MB (seated 0.05 mm, drilled)", "board-5mb-rims": "corpus 5 MB, pins 0.1 mm from their rims",
         "board-40mb": "corpus 40 MB (seated 0.05 mm, drilled)",
         "board-150mb": "corpus 174 MB (seated 0.05 mm, drilled)",
         "seated": "5 MB models, seated 0.05 mm, declared 0.01", "seated-occt": "5 MB models, seated 0.05 mm, declared 0.01",
         "sunk": "5 MB models, sunk 0.025 mm, declared 0.01"}
print("| board | options | mode | reported: penetrating / touching / undecided | open after the triangles | "
      "decided: analytic / refined / exact | dismissed | faces refined | decision steps ms: witness / depth / hull / refine / exact | "
      "query ms | end to end s |")
print("|---|---|---|---|---:|---|---:|---:|---|---:|---:|")
notes = []
def median_run(name, mode, repeats):
    js = [json.load(open(os.path.join(out, f"{name}-{mode}-{i}.json"))) for i in range(1, repeats + 1)]
    js.sort(key=lambda j: j["timings"]["total"])
    return js[len(js) // 2]

for line in open(os.path.join(out, "runs.txt")):
    name, path, options, repeats = line.rstrip("\n").split("|")
    runs = {}
    for mode in ("certified", "fast"):
        j = median_run(name, mode, int(repeats))
        json.dump(j, open(os.path.join(out, f"{name}-{mode}.json"), "w"))  # the run shown (results_summary.py)
        runs[mode] = j
        s, c, t = j["summary"], j["counters"], j["timings"]
        q = 1000 * t["total"]
        e2e = j["import_timings"]["seconds"] + t["total"]
        mb = os.path.getsize(path) / 1e6
        steps = " / ".join(f"{1000 * t.get('decide_' + k, 0):.1f}" for k in ("witness", "depth", "hull", "refine", "exact"))
        decided = f"{c['decided_analytic']} / {c['decided_refined']} / {c['decided_exact']}"
        if mode == "fast":
            decided, steps = "–", "–"
        print(f"| {label.get(name, name)} ({mb:.1f} MB) | {options or 'defaults'} | {mode} | "
              f"{s['penetrating']} / {s['touching']} / {s['undecided']} | {c['ambiguous_pairs']} | {decided} | "
              f"{c['dismissed_pairs']} | {c['refined_surfaces']} | {steps} | {q:.0f} | {e2e:.2f} |")
    cq, fq = runs["certified"]["timings"]["total"], runs["fast"]["timings"]["total"]
    ce = runs["certified"]["import_timings"]["seconds"] + cq
    fe = runs["fast"]["import_timings"]["seconds"] + fq
    goal_q = cq <= 3 * fq + 0.020
    goal_e = ce <= 1.1 * fe
    notes.append(f"{label.get(name, name)}, {options or 'defaults'}: certified query {1000 * cq:.0f} ms against "
                 f"--fast {1000 * fq:.0f} ms ({'within' if goal_q else 'OUTSIDE'} 3x + 20 ms); end to end "
                 f"{ce:.2f} s against {fe:.2f} s ({ce / fe:.2f}x, {'within' if goal_e else 'OUTSIDE'} 1.1x).")
print()
for n in notes:
    print(f"- {n}")
PY
