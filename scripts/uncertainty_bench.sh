#!/usr/bin/env bash
# The model-uncertainty band on real-part boards (docs/results.md, "The model-uncertainty band on a
# real-part board"; issue 39): board-5mb's KiCad models (scripts/make_corpus.sh) placed again with
# the length uncertainty KiCad declares (0.01 mm), once seated 0.05 mm above the board and once sunk
# 0.025 mm into it, each checked certified with the uncertainty from the file (auto) and from OCCT's
# tolerances alone (occt), and --fast, in one run. Writes a Markdown table on stdout.
#   bash scripts/uncertainty_bench.sh [BUILD_DIR] [OUT_DIR]
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-$root/build}
out=${2:-$root/out/uncertainty_bench}
list=$root/out/corpus/board-5mb.models
generator=$build/bench/make_board_assembly
cadclash=$build/tools/cadclash
if [ ! -f "$list" ] || [ ! -x "$generator" ] || [ ! -x "$cadclash" ]; then
  echo "_No KiCad board corpus in this tree (bash scripts/make_corpus.sh), or make_board_assembly / cadclash not built._"
  exit 0
fi
mkdir -p "$out"
# name, seat (mm above the board's top; negative: sunk), tolerance
runs=("seated 0.05 0.04" "sunk -0.025 0")
for r in "${runs[@]}"; do
  read -r name seat tolerance <<<"$r"
  board=$out/board-$name.step
  "$generator" --out "$board" --placements 150 --seed 5 --name board --list "$list" --seat "$seat" \
    --uncertainty 0.01 >"$out/board-$name.log"
  for mode in auto occt fast; do
    args=(--uncertainty auto)
    if [ "$mode" = occt ]; then args=(--uncertainty occt); fi
    if [ "$mode" = fast ]; then args=(--fast); fi
    "$cadclash" check "$board" --tolerance "$tolerance" --threads 2 -q "${args[@]}" --json "$out/$name-$mode.json" \
      >/dev/null 2>"$out/$name-$mode.err" || true
  done
done
python3 - "$out" <<'PY'
import json, sys
out = sys.argv[1]
def key(p):
    return (p["a"]["instance"], p["b"]["instance"], p["a"].get("step_id"), p["b"].get("step_id"))
print("| board (KiCad models, declared uncertainty 0.01 mm) | tolerance | mode | pairs | penetrating | touching | undecided | within the tolerance | only within the uncertainty | either | query ms | end to end s (import + query) |")
print("|---|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
notes = []
for name, seat, tol in (("seated", "0.05 mm above", "0.04"), ("sunk", "0.025 mm into the board", "0")):
    runs = {}
    for mode in ("auto", "occt", "fast"):
        j = json.load(open(f"{out}/{name}-{mode}.json"))
        runs[mode] = j
        s = j["summary"]
        w = s.get("contact_within", {})
        label = {"auto": "certified, uncertainty from the file", "occt": "certified, OCCT tolerances only",
                 "fast": "--fast (triangles, no uncertainty)"}[mode]
        q = 1000 * j["timings"]["total"] if "timings" in j else float("nan")
        e2e = j["import_timings"]["seconds"] + q / 1000 if "import_timings" in j else float("nan")
        print(f"| {seat} | {tol} | {label} | {s['pairs']} | {s['penetrating']} | {s['touching']} | {s['undecided']} | "
              f"{w.get('tolerance', 0)} | {w.get('model uncertainty', 0)} | {w.get('unknown', 0)} | {q:.0f} | {e2e:.2f} |")
    if name == "sunk":
        cert = {key(p): p for p in runs["auto"]["pairs"]}
        deep = [p for p in runs["fast"]["pairs"] if p["class"] == "penetrating" and p["penetration"] > 0.02]
        proved = sum(1 for p in deep if cert.get(key(p), {}).get("class") == "penetrating")
        depths = [p["penetration"] for p in runs["auto"]["pairs"] if p["class"] == "penetrating"]
        by = {}
        for p in runs["auto"]["pairs"]:
            if p["class"] == "penetrating":
                by[p["decided_by"]] = by.get(p["decided_by"], 0) + 1
        notes.append(f"Sunk board, certified: of the {len(deep)} face pairs whose triangles cross deeper than "
                     f"T = 0.02 mm (as `--fast` measures them), {proved} are proved penetrating; the proved depths "
                     f"of all {len(depths)} penetrating pairs lie in [{min(depths) if depths else 0:.4f}, "
                     f"{max(depths) if depths else 0:.4f}] mm (every component is sunk 0.025 mm); decided by "
                     + ", ".join(f"{k} {v}" for k, v in sorted(by.items())) + ".")
print()
for n in notes:
    print(n)
PY
