#!/usr/bin/env bash
# Import of large real assemblies against the plain OCCT pipeline (issue 38; docs/import.md, "Large
# assemblies: the KiCad board corpus"). For each of out/corpus/*.step (scripts/make_corpus.sh) and
# data/external/as1-tu-203.stp (when there), REPEATS rounds, alternating in each round
#   - `cadclash check FILE --json` (default settings: deflection 0.1 mm, certified decisions);
#   - occt_pipeline_peer FILE (STEPCAFControl_Reader, Transfer, BRepMesh_IncrementalMesh at
#     0.1 mm / 0.5 rad with its parallel flag on each distinct leaf shape: what a FreeCAD or
#     CadQuery user's import does);
# so that a change in the machine's load falls on both alike. Per file: the median wall time of each,
# the stage times of the median run, MB/s, the ratio peer / cadclash, and the peak RSS (/usr/bin/time
# %M: for cadclash the largest of its process and its isolated reader child).
#   bash scripts/import_peer_bench.sh [BUILD_DIR] [REPEATS]
# BUILD_DIR (default build/) must hold tools/cadclash; the peer is $OCCT_PEER when set (a build of
# bench/ elsewhere), else BUILD_DIR/bench/occt_pipeline_peer, built there if missing. Writes out/import_peer_bench/results.md and results.json. Numbers are printed, never
# judged; this is not a test.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-$root/build}
repeats=${2:-3}
out=$root/out/import_peer_bench
cadclash=$build/tools/cadclash
peer=${OCCT_PEER:-$build/bench/occt_pipeline_peer}
cd "$root"
if [ ! -x "$cadclash" ]; then
  echo "import_peer_bench: $cadclash is missing (build the cadclash target first)" >&2
  exit 1
fi
if [ ! -x "$peer" ] && [ -z "${OCCT_PEER:-}" ]; then cmake --build "$build" --target occt_pipeline_peer >/dev/null; fi
if [ ! -x "$peer" ]; then
  echo "import_peer_bench: $peer is missing" >&2
  exit 1
fi
if [ ! -x /usr/bin/time ]; then  # GNU time: the peak RSS of a process and its children
  sudo_cmd=()
  if [ "$(id -u)" != 0 ]; then sudo_cmd=(sudo); fi
  "${sudo_cmd[@]}" apt-get update -qq
  DEBIAN_FRONTEND=noninteractive "${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends time >/dev/null
fi
files=()
# BENCH_FILES (space-separated paths) replaces the default list.
for f in ${BENCH_FILES:-out/corpus/*.step data/external/as1-tu-203.stp}; do
  if [ -f "$f" ]; then files+=("$f"); fi
done
if [ ${#files[@]} -eq 0 ]; then
  echo "import_peer_bench: no input (run scripts/make_corpus.sh first)" >&2
  exit 1
fi
rm -rf "$out"
mkdir -p "$out/runs"
load=$(cut -d" " -f1-3 /proc/loadavg)
commit=$(git -C "$root" rev-parse --short HEAD 2>/dev/null || echo unknown)
[ -z "$(git -C "$root" status --porcelain --untracked-files=no 2>/dev/null)" ] || commit="$commit with local changes"

# One run: wall seconds, peak RSS in KiB, exit code and the JSON in runs/. cadclash's exit 3 (clashes
# found) is a result, and so is 1 when the report was written: an input error (a face OCCT cannot
# mesh) is part of what real files do; its diagnostics are in the report and counted in the table.
run() {  # run TOOL FILE K
  local tool=$1 file=$2 k=$3 id t0 t1 rc
  id=$(basename "$file")-$tool-$k
  t0=$(date +%s.%N)
  set +e
  if [ "$tool" = cadclash ] || [ "$tool" = cadclash1 ]; then
    local threads=()
    [ "$tool" = cadclash1 ] && threads=(--threads 1)
    /usr/bin/time -f %M -o "$out/runs/$id.rss" python3 "$root/scripts/tree_memory.py" "$out/runs/$id.pss" \
      "$cadclash" check "$file" "${threads[@]}" --json "$out/runs/$id.json" >"$out/runs/$id.txt" 2>"$out/runs/$id.err"
  else
    /usr/bin/time -f %M -o "$out/runs/$id.rss" python3 "$root/scripts/tree_memory.py" "$out/runs/$id.pss" \
      "$peer" "$file" >"$out/runs/$id.json" 2>"$out/runs/$id.err"
  fi
  rc=$?
  set -e
  t1=$(date +%s.%N)
  echo $rc >"$out/runs/$id.rc"
  if [ $rc -ne 0 ] && ! { [ "$tool" != peer ] && { [ $rc -eq 3 ] || { [ $rc -eq 1 ] && [ -s "$out/runs/$id.json" ]; }; }; }; then
    echo "import_peer_bench: $tool on $file exited $rc (see $out/runs/$id.err)" >&2
    exit 1
  fi
  awk -v a="$t0" -v b="$t1" 'BEGIN { printf "%.3f\n", b - a }' >"$out/runs/$id.wall"
}
# cadclash on one thread too (what reading one file on every core gains), for files up to 60 MB (the
# 174 MB board's single-thread runs would double the bench's time).
tools_of() {
  if [ "$(stat -c %s "$1")" -le 60000000 ]; then echo cadclash cadclash1 peer; else echo cadclash peer; fi
}
for f in "${files[@]}"; do
  for ((k = 0; k < repeats; k++)); do
    for tool in $(tools_of "$f"); do
      echo "import_peer_bench: $f, round $((k + 1)) of $repeats, $tool" >&2
      run "$tool" "$f" "$k"
    done
  done
done

python3 - "$out" "$repeats" "$(nproc)" "$load" "$commit" "${files[@]}" <<'PY'
import json, os, statistics, sys

out, repeats, cores, load, commit, files = sys.argv[1], int(sys.argv[2]), sys.argv[3], sys.argv[4], sys.argv[5], sys.argv[6:]

def runs(file, tool):
    base = os.path.join(out, "runs", os.path.basename(file) + "-" + tool)
    rows = []
    for k in range(repeats):
        with open(f"{base}-{k}.wall") as w, open(f"{base}-{k}.rss") as r, open(f"{base}-{k}.json") as j:
            rows.append({"wall": float(w.read()), "rss_mb": int(r.read().split()[-1]) / 1024, "json": json.load(j),
                         "rc": int(open(f"{base}-{k}.rc").read()),
                         "tree_mb": int(open(f"{base}-{k}.pss").read()) / 1024})
        rows[-1]["k"] = k
    rows.sort(key=lambda row: row["wall"])
    return rows[(repeats - 1) // 2], rows  # the median run (the lower one for an even count)

results = []
for f in files:
    size = os.path.getsize(f)
    (c, c_all), (p, p_all) = runs(f, "cadclash"), runs(f, "peer")
    imp = c["json"]["import_timings"]["files"][0]
    cad = {"wall_s": c["wall"], "walls_s": [r["wall"] for r in c_all], "peak_rss_mb": round(c["rss_mb"], 1),
           "peak_tree_pss_mb": round(max(r["tree_mb"] for r in c_all), 1),
           "read_s": imp["read"], "transfer_s": imp["transfer"], "heal_s": imp["heal"],
           "tessellate_s": imp["tessellate"], "import_s": imp["total"], "query_s": c["json"]["timings"]["total"],
           "query_tessellation_s": c["json"]["timings"]["tessellation"],
           "exit_code": c["rc"], "complete": c["json"]["complete"], "pairs": c["json"]["summary"]["pairs"],
           "diagnostics": c["json"]["diagnostics"]}
    pj = p["json"]
    per = {"wall_s": p["wall"], "walls_s": [r["wall"] for r in p_all], "peak_rss_mb": round(p["rss_mb"], 1),
           "peak_tree_pss_mb": round(max(r["tree_mb"] for r in p_all), 1),
           "read_s": pj["read_s"], "transfer_s": pj["transfer_s"], "mesh_s": pj["mesh_s"], "total_s": pj["total_s"],
           "parts": pj["parts"], "faces": pj["faces"], "triangles": pj["triangles"]}
    one = None
    if os.path.exists(os.path.join(out, "runs", os.path.basename(f) + "-cadclash1-0.wall")):
        o, o_all = runs(f, "cadclash1")
        oimp = o["json"]["import_timings"]["files"][0]
        one = {"wall_s": o["wall"], "walls_s": [r["wall"] for r in o_all], "import_s": oimp["total"],
               "efficiency": o["wall"] / (int(cores) * c["wall"]), "import_efficiency": oimp["total"] / (int(cores) * imp["total"])}
    cad["processes"] = imp.get("processes", 1)
    # Which round each tool's median run was (runs/FILE-TOOL-K.json; scripts/import_core_model.py).
    medians = {"cadclash": c["k"], "peer": p["k"]}
    if one:
        medians["cadclash1"] = o["k"]
    results.append({"file": f, "size_bytes": size, "median_runs": medians, "cadclash": cad, "cadclash_one_thread": one, "peer": per,
                    "mb_per_s": {"cadclash": size / 1e6 / cad["wall_s"], "peer": size / 1e6 / per["wall_s"]},
                    "peer_over_cadclash": {"wall": per["wall_s"] / cad["wall_s"], "import": per["total_s"] / cad["import_s"]}})

with open(os.path.join(out, "results.json"), "w") as j:
    json.dump({"commit": commit, "repeats": repeats, "cores": int(cores), "load_before": load, "files": results}, j, indent=1)

ms = lambda s: f"{s * 1e3:.0f}"
with open(os.path.join(out, "results.md"), "w") as md:
    md.write(f"cadclash at {commit}; {cores} cores (load average before the runs: {load}), median of {repeats} run(s) per tool, alternating. "
             "cadclash: `cadclash check FILE` (import, healing, tessellation at 0.1 mm, certified collision query); "
             "peer: `occt_pipeline_peer FILE` (STEPCAFControl_Reader ReadFile and Transfer, BRepMesh_IncrementalMesh "
             "0.1 mm / 0.5 rad in parallel on each distinct leaf shape; OCCT's own healing at transfer but no BRepCheck pass, no query). Wall time of the whole "
             "process; stages of the median run in ms (a build that tessellates lazily meshes inside query, "
             "`timings.tessellation` in results.json, and shows tessellate 0); MB/s is file size over wall time; peer/cadclash > 1: cadclash "
             "is faster (wall: whole runs; import: the peer's total against cadclash's import, query left out); "
             "RSS: /usr/bin/time peak, the largest single process (cadclash's or its isolated reader's or a worker's); "
             "memory: the peak over the run of the whole process tree's summed proportional set size (scripts/tree_memory.py, "
             "sampled every 100 ms, the largest of the rounds), what the machine must hold; "
             "cadclash exit / pairs / diagnostics: its exit code (1: an input error, e.g. a face OCCT could not mesh), the "
             "reported surface pairs and the import diagnostics.\n\n")
    md.write("| file | MB | cadclash wall s | cadclash 1 thread wall s (efficiency) | peer wall s | peer/cadclash wall | peer/cadclash import | cadclash read / transfer / heal / tessellate / query | "
             "peer read / transfer / mesh | MB/s cadclash | MB/s peer | RSS MB cadclash | RSS MB peer | memory MB cadclash / peer | faces | triangles (peer) | cadclash exit / pairs / diagnostics |\n")
    md.write("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n")
    for r in results:
        c, p = r["cadclash"], r["peer"]
        one = r["cadclash_one_thread"]
        one_text = f"{one['wall_s']:.2f} ({100 * one['efficiency']:.0f} %)" if one else "not run"
        md.write(f"| {os.path.basename(r['file'])} | {r['size_bytes'] / 1e6:.1f} | {c['wall_s']:.2f} | {one_text} | {p['wall_s']:.2f} | "
                 f"{r['peer_over_cadclash']['wall']:.2f} | {r['peer_over_cadclash']['import']:.2f} | "
                 f"{ms(c['read_s'])} / {ms(c['transfer_s'])} / {ms(c['heal_s'])} / {ms(c['tessellate_s'])} / {ms(c['query_s'])} | "
                 f"{ms(p['read_s'])} / {ms(p['transfer_s'])} / {ms(p['mesh_s'])} | "
                 f"{r['mb_per_s']['cadclash']:.1f} | {r['mb_per_s']['peer']:.1f} | {c['peak_rss_mb']:.0f} | {p['peak_rss_mb']:.0f} | "
                 f"{c['peak_tree_pss_mb']:.0f} / {p['peak_tree_pss_mb']:.0f} | "
                 f"{p['faces']} | {p['triangles']} | {c['exit_code']} / {c['pairs']} / {len(c['diagnostics'])} |\n")
    md.write("\nEfficiency: the 1-thread wall time over (cores x the default run's), the whole check; "
             f"time against file size: [import_time.svg](import_time.svg).\n")
# Time against file size, per tool and stage, for gnuplot: MB, cadclash wall, its read, transfer, heal,
# query, peer wall, its read, transfer, mesh.
with open(os.path.join(out, "import_time.dat"), "w") as d:
    for r in sorted(results, key=lambda r: r["size_bytes"]):
        c, p = r["cadclash"], r["peer"]
        d.write(f"{r['size_bytes'] / 1e6:.3f} {c['wall_s']} {c['read_s']} {c['transfer_s']} {c['heal_s']} {c['query_s']} "
                f"{p['wall_s']} {p['read_s']} {p['transfer_s']} {p['mesh_s']}\n")
PY
if command -v gnuplot >/dev/null; then
  gnuplot <<GP
set terminal svg size 760,440 dynamic font "sans,11"
set output "$out/import_time.svg"
set logscale xy
set xlabel "STEP file size, MB"
set ylabel "seconds"
set key left top
set grid
set title "Import and check against the plain OCCT pipeline, $(nproc) cores"
plot "$out/import_time.dat" using 1:2 with linespoints lw 2 title "cadclash check (whole command)", \
     "" using 1:3 with lines dt 2 title "cadclash read", "" using 1:4 with lines dt 3 title "cadclash transfer", \
     "" using 1:5 with lines dt 4 title "cadclash heal", \
     "" using 1:7 with linespoints lw 2 title "OCCT read + transfer + mesh (whole command)", \
     "" using 1:8 with lines dt 2 title "OCCT read", "" using 1:9 with lines dt 3 title "OCCT transfer", \
     "" using 1:10 with lines dt 4 title "OCCT mesh"
GP
fi
# The model of more cores from the median runs' measured costs (appended to results.md).
python3 "$root/scripts/import_core_model.py" "$out"
cat "$out/results.md"
