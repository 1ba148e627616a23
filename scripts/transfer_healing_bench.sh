#!/usr/bin/env bash
# OCCT's shape healing at transfer, measured (issue 38 item 3; docs/import.md, "Healing at transfer"):
# for each file, REPEATS rounds of `cadclash check FILE --tolerance T` with and without
# --no-transfer-healing, alternating in each round so that a change in the machine's load falls on both
# alike. Per file: the median wall time of each, the faces the per-part check healed one by one (the
# "failed BRepCheck" warnings), the surface pairs within T, and whether both runs report the same pairs
# (instance paths, STEP #ids and contact class), and the faces read each way (cadclash info).
#   bash scripts/transfer_healing_bench.sh [BUILD_DIR] [REPEATS]
# Files: data/external's STEP samples and out/corpus/board-{5mb,40mb}.step when there (BENCH_FILES,
# space-separated, replaces the list); T = 0.5 mm (HEALING_BENCH_TOLERANCE), so that the boards'
# components report the board's faces they sit on. Writes out/transfer_healing_bench/results.md.
# Numbers are printed, never judged; this is not a test.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-$root/build}
repeats=${2:-3}
tolerance=${HEALING_BENCH_TOLERANCE:-0.5}
out=$root/out/transfer_healing_bench
cadclash=$build/tools/cadclash
[ -x "$cadclash" ] || { echo "transfer_healing_bench: $cadclash is missing (build the cadclash target)" >&2; exit 1; }
if [ -n "${BENCH_FILES:-}" ]; then
  read -r -a files <<<"$BENCH_FILES"
else
  files=()
  for f in as1-tu-203.stp component8.step frame.step linkrods.step screw.step t20_data.step; do
    [ -f "$root/data/external/$f" ] && files+=("$root/data/external/$f")
  done
  for f in board-5mb board-40mb; do
    [ -f "$root/out/corpus/$f.step" ] && files+=("$root/out/corpus/$f.step")
  done
fi
[ ${#files[@]} -gt 0 ] || { echo "transfer_healing_bench: no input (bash scripts/setup.sh; bash scripts/make_corpus.sh)" >&2; exit 1; }
rm -rf "$out" && mkdir -p "$out"

run() {  # run FILE MODE ROUND
  local name flag=() start end
  name=$(basename "$1")
  [ "$2" = off ] && flag=(--no-transfer-healing)
  start=$(date +%s.%N)
  "$cadclash" check "$1" --tolerance "$tolerance" --no-timings "${flag[@]}" --json "$out/$name.$2.$3.json" \
    >/dev/null 2>"$out/$name.$2.$3.err" || true
  end=$(date +%s.%N)
  echo "$name $2 $3 $(echo "$end - $start" | bc)" >>"$out/walls.txt"
}

for f in "${files[@]}"; do
  echo "transfer_healing_bench: $(basename "$f")" >&2
  # The faces each way (cadclash info, untimed): healing at transfer may split or merge faces.
  "$cadclash" info "$f" --lazy >"$out/$(basename "$f").on.info" 2>/dev/null || true
  "$cadclash" info "$f" --lazy --no-transfer-healing >"$out/$(basename "$f").off.info" 2>/dev/null || true
  for round in $(seq 1 "$repeats"); do
    if [ $((round % 2)) = 1 ]; then run "$f" on "$round"; run "$f" off "$round"
    else run "$f" off "$round"; run "$f" on "$round"; fi
  done
done

python3 - "$out" "$(git -C "$root" rev-parse --short HEAD)" "$tolerance" "$repeats" "${files[@]}" <<'PY'
import json, os, sys
out, commit, tolerance, repeats = sys.argv[1:5]
files = sys.argv[5:]
walls = {}
for line in open(out + '/walls.txt'):
    name, mode, round_, wall = line.split()
    walls.setdefault((name, mode), []).append((float(wall), round_))
def pairs(j):
    # By STEP #id, not face index: healing may split a face (the pieces keep its #id).
    key = lambda s: (s['instance'], s.get('step_id', -1))
    return sorted((key(p['a']), key(p['b']), p['class']) for p in j['pairs'])
rows = ['| file | MB | with healing s | without s | saved | faces healed one by one (with / without) | pairs within %s mm | same pairs (by STEP #id) | faces (with / without) |' % tolerance,
        '|---|---:|---:|---:|---:|---|---:|---|---|']
def faces(name, m):
    first = open(f'{out}/{name}.{m}.info').readline().split()
    return first[first.index('surfaces') - 1] if 'surfaces' in first else '?'
for f in files:
    name = os.path.basename(f)
    med = {}
    for mode in ('on', 'off'):
        v = sorted(walls[(name, mode)])
        med[mode] = v[len(v) // 2]
    j = {m: json.load(open(f'{out}/{name}.{m}.{med[m][1]}.json')) for m in ('on', 'off')}
    healed = {m: sum('failed BRepCheck' in l for l in open(f'{out}/{name}.{m}.{med[m][1]}.err')) for m in ('on', 'off')}
    same_pairs = pairs(j['on']) == pairs(j['off'])
    on, off = med['on'][0], med['off'][0]
    rows.append(f"| {name} | {os.path.getsize(f) / 1e6:.1f} | {on:.2f} | {off:.2f} | {100 * (on - off) / on:.0f} % | "
                f"{healed['on']} / {healed['off']} | {len(j['on']['pairs'])} | {'yes' if same_pairs else 'NO'} | "
                f"{faces(name, 'on')} / {faces(name, 'off')} |")
text = (f"OCCT's shape healing at transfer (cadclash {commit}, `check --tolerance {tolerance}` with and without "
        f"`--no-transfer-healing`, median of {repeats} alternating rounds):\n\n") + '\n'.join(rows) + '\n'
open(out + '/results.md', 'w').write(text)
print(text)
PY
