#!/usr/bin/env bash
# The import cache on re-runs of a large real assembly (issue 38 item 5; docs/import.md, "A cache per
# product"). For one board of out/corpus (scripts/make_corpus.sh; default board-40mb.step), copied
# into out/import_cache_bench/ so that edits keep its path, `cadclash check --cache DIR --json`:
#   cold        an empty cache;
#   unchanged   the same file again (its whole entry);
#   placement   the last occurrence's placement lifted 0.5 mm along z (the main text changed: the
#               placements entry gives the file's model with its poses recomputed);
#   model       the first product's vertex moved 1e-9 mm (the board plate's geometry changed);
#   component   the last product's vertex moved 1e-9 mm (one component model's geometry changed);
#   renumbered  every id + 1,000,000 (another export of the same products).
# Per run: wall time, its share of the cold run, the import's stages, pieces and parts from the cache.
#   bash scripts/import_cache_bench.sh [BUILD_DIR] [BOARD] [ROUNDS]
# ROUNDS (default 3) times the whole sequence from an empty cache; per run the median wall time and
# the stages of the median round. Writes out/import_cache_bench/results.md (IMPORT_CACHE_BENCH_OUT
# names another folder). Numbers are printed, never judged; this is not a test.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-$root/build}
board=${2:-$root/out/corpus/board-40mb.step}
rounds=${3:-3}
out=${IMPORT_CACHE_BENCH_OUT:-$root/out/import_cache_bench}
cadclash=$build/tools/cadclash
[ -x "$cadclash" ] || { echo "import_cache_bench: $cadclash is missing (build the cadclash target)" >&2; exit 1; }
[ -f "$board" ] || { echo "import_cache_bench: $board is missing (bash scripts/make_corpus.sh)" >&2; exit 1; }
rm -rf "$out" && mkdir -p "$out"
file=$out/board.step
cache=$out/cache
cp "$board" "$out/original.step"

edit() {  # edit KIND: writes $file from the original
  python3 - "$out/original.step" "$file" "$1" <<'PY'
import re, sys
src, dst, kind = sys.argv[1:]
t = open(src).read()
def point_of(ref_statement_pattern, nth, last=False):
    ms = list(re.finditer(ref_statement_pattern, t))
    m = ms[-1] if last else ms[0]
    refs = re.findall(r'#(\d+)', t[m.start():t.index(';', m.start())])
    return refs[nth]
def move_point(pid, axis, d):
    global t
    m = re.search(r'\n#' + pid + r' = CARTESIAN_POINT\((\'[^\']*\'),\(([^)]*)\)\);', t)
    c = m.group(2).split(',')
    c[axis] = '%.16E' % (float(c[axis]) + d)  # a STEP real needs its '.'
    t = t[:m.start()] + '\n#' + pid + ' = CARTESIAN_POINT(' + m.group(1) + ',(' + ','.join(c) + '));' + t[m.end():]
if kind == 'placement':  # the last occurrence lifted 0.5 mm (away from the board: no new contact)
    placement = point_of(r'#\d+ = ITEM_DEFINED_TRANSFORMATION\(', 2, last=True)
    move_point(point_of(r'\n#' + placement + r' = AXIS2_PLACEMENT_3D\(', 1), 2, 0.5)
elif kind == 'model':
    move_point(point_of(r'#\d+ = VERTEX_POINT\(', 1), 0, 1e-9)
elif kind == 'component':
    move_point(point_of(r'#\d+ = VERTEX_POINT\(', 1, last=True), 0, 1e-9)
elif kind == 'renumbered':
    data = t.index('DATA;')
    parts = re.split(r"('(?:[^']|'')*')", t[data:])
    parts = [p if i % 2 else re.sub(r'#(\d+)', lambda m: '#' + str(int(m.group(1)) + 1000000), p) for i, p in enumerate(parts)]
    t = t[:data] + ''.join(parts)
open(dst, 'w').write(t)
PY
}

run() {  # run NAME ROUND
  local start end
  start=$(date +%s.%N)
  "$cadclash" check "$file" --cache "$cache" --json "$out/$1.$2.json" >/dev/null 2>"$out/$1.$2.err" || true
  end=$(date +%s.%N)
  echo "$1 $2 $(echo "$end - $start" | bc)" >>"$out/walls.txt"
}

for round in $(seq 1 "$rounds"); do
  rm -rf "$cache"
  cp "$out/original.step" "$file"
  run cold "$round"
  run unchanged "$round"
  for kind in placement model component renumbered; do
    edit "$kind"
    run "$kind" "$round"
  done
done

python3 - "$out" "$(git -C "$root" rev-parse --short HEAD)" "$board" <<'PY'
import json, sys
out, commit, board = sys.argv[1:]
runs = {}
for line in open(out + '/walls.txt'):
    name, round_, wall = line.split()
    runs.setdefault(name, []).append((float(wall), round_))
median = {name: sorted(v)[len(v) // 2] for name, v in runs.items()}  # (wall, round)
cold = median['cold'][0]
rows = ['| run | wall s | of cold | import s (read / transfer / heal) | query s | pieces cached | parts cached |',
        '|---|---:|---:|---|---:|---:|---:|']
for name in ['cold', 'unchanged', 'placement', 'model', 'component', 'renumbered']:
    wall, round_ = median[name]
    j = json.load(open(f'{out}/{name}.{round_}.json'))
    f = j['import_timings']['files'][0]
    q = j.get('timings', {}).get('total', 0.0)
    pieces = {'hit': 'whole file', 'placements': "file's model, poses recomputed"}.get(
        f['cache'], f"{f.get('pieces_cached', 0)} / {f.get('pieces', 0)}")
    rows.append(f"| {name} | {wall:.2f} | {100 * wall / cold:.0f} % | {f['total']:.2f} ({f['read']:.2f} / "
                f"{f['transfer']:.2f} / {f['heal']:.2f}) | {q:.2f} | {pieces} | {f.get('parts_cached', 0)} |")
text = (f"Import cache on re-runs of {board.split('/')[-1]} (cadclash {commit}, `check --cache`, default settings; "
        f"median of {len(runs['cold'])} rounds, each from an empty cache):\n\n") + '\n'.join(rows) + '\n'
open(out + '/results.md', 'w').write(text)
print(text)
PY
