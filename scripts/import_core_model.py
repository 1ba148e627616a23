#!/usr/bin/env python3
"""A model of `cadclash check FILE` on more cores, from the costs one run measured (issue 38).

    python3 scripts/import_core_model.py OUT_DIR      # OUT_DIR: scripts/import_peer_bench.sh's output

For each file of OUT_DIR/results.json whose median cadclash run read the file in pieces, it takes
that run's import_timings (docs/report-schema.md: piece_costs, part_heal_seconds) and predicts the
whole check's wall time on P cores:

  wall(P) = rest + split + window(P) + after + heal(P) + query(P)

- rest: the process outside import and query (start-up, writing the report), as measured;
- split: cutting the text and the cache's lookups, serial, as measured;
- window(P): the pieces' workers and the main text's parse, which run at once. The pieces are shared
  out over P workers as cadclash shares them (share_pieces: by weight, largest first onto the least
  loaded), each worker's load the sum of its pieces' measured CPU seconds; the main parse takes a
  core too, so window(P) = max(largest worker load, main parse, (all loads + main parse) / P), plus
  what the measured window took beyond that model at the run's own core count (forks, pipes);
- after: the rest of the reader (binding, OCCT's transfer of the assembly, the document's trip back,
  the assembly walk), serial, as measured;
- heal(P): the parts' measured check-and-heal times dealt as OpenMP's dynamic schedule deals them
  (in order, each to the first free thread), plus the measured heal's time beyond that at the run's
  core count;
- query(P): Amdahl's law fitted to the 1-thread and the default run's query times (held at the
  default run's time when there is no 1-thread run).

The peer (plain OCCT: read, transfer, then BRepMesh with its parallel flag) is modelled generously:
read and transfer serial as measured, its meshing perfectly parallel. Also shown: the same model with
the pieces shared by their measured cost instead of their bytes (what a scheduler that knew the costs
would give). The largest piece bounds window(P) from below whatever the cores. Appends a section to
OUT_DIR/results.md and writes OUT_DIR/core_model.json. Prints, never judges.
"""
import heapq
import json
import os
import sys

CORES = [1, 2, 4, 8, 16, 32]


def share_by(weights, which, workers):
    """share_pieces (step_split_text.cpp): largest first onto the least loaded (ties: lower index)."""
    used = min(workers, len(which))
    if used == 0:
        return []
    order = sorted(which, key=lambda p: -weights[p])  # stable: ties keep index order
    load = [0] * used
    shares = [[] for _ in range(used)]
    for p in order:
        w = min(range(used), key=lambda i: (load[i], i))
        load[w] += weights[p] + 1
        shares[w].append(p)
    return shares


def window(costs, workers, by_cost=False):
    seconds = costs["seconds"]
    which = [p for p, s in enumerate(seconds) if s > 0]
    weights = [round(s * 1e6) for s in seconds] if by_cost else costs.get("weights", costs["bytes"])
    loads = [sum(seconds[p] for p in share) for share in share_by(weights, which, workers)]
    main = costs["main_parse"]
    return max([main, (sum(loads) + main) / workers] + loads)


def dynamic_schedule(times, threads):
    """OpenMP schedule(dynamic, 1): parts in order, each to the thread that is free first."""
    if not times:
        return 0.0
    free = [0.0] * min(threads, len(times))
    for t in times:
        heapq.heapreplace(free, free[0] + t)
    return max(free)


def model(run, one_thread_query, measured_wall, cores_run):
    f = run["import_timings"]["files"][0]
    costs = f["piece_costs"]
    heal_times = f.get("part_heal_seconds", [])
    query = run["timings"]["total"]
    rest = measured_wall - f["total"] - query
    after = f["total"] - f["heal"] - f["tessellate"] - costs["split"] - costs["workers"]
    window_extra = max(0.0, costs["workers"] - window(costs, cores_run))
    heal_extra = max(0.0, f["heal"] - dynamic_schedule(heal_times, cores_run))
    if one_thread_query is not None and cores_run > 1:
        parallel = max(0.0, (one_thread_query - query) * cores_run / (cores_run - 1))
        serial = max(0.0, one_thread_query - parallel)
    else:
        parallel, serial = 0.0, query

    def wall(p, by_cost=False):
        w = window(costs, p, by_cost) + window_extra
        h = dynamic_schedule(heal_times, p) + heal_extra
        q = serial + parallel / p
        imp = costs["split"] + w + after + h + f["tessellate"]
        return {"wall": rest + imp + q, "import": imp, "window": w, "heal": h, "query": q}

    parts = {"rest": rest, "split": costs["split"], "after": after, "window_extra": window_extra,
             "heal_extra": heal_extra, "query_serial": serial, "query_parallel": parallel,
             "largest_piece": max(costs["seconds"]) if costs["seconds"] else 0.0,
             "pieces_cpu": sum(costs["seconds"]), "main_parse": costs["main_parse"],
             "heal_cpu": sum(heal_times), "largest_part_heal": max(heal_times) if heal_times else 0.0,
             "pieces": len(costs["seconds"])}
    return parts, {p: wall(p) for p in CORES}, {p: wall(p, True) for p in CORES}


def main():
    out = sys.argv[1]
    with open(os.path.join(out, "results.json")) as j:
        bench = json.load(j)
    cores_run = bench["cores"]
    rows = []
    for r in bench["files"]:
        name = os.path.basename(r["file"])
        k = r.get("median_runs")
        if not k:
            continue
        with open(os.path.join(out, "runs", f"{name}-cadclash-{k['cadclash']}.json")) as j:
            run = json.load(j)
        files = run.get("import_timings", {}).get("files", [])
        if len(files) != 1 or not files[0].get("piece_costs"):
            continue  # not read in pieces (a small file): nothing to model
        one_query = one_import = None
        if "cadclash1" in k:
            with open(os.path.join(out, "runs", f"{name}-cadclash1-{k['cadclash1']}.json")) as j:
                one = json.load(j)
            one_query = one["timings"]["total"]
            one_import = one["import_timings"]["files"][0]["total"]
        parts, by_bytes, by_cost = model(run, one_query, r["cadclash"]["wall_s"], cores_run)
        peer = r["peer"]
        peer_rest = peer["wall_s"] - peer["total_s"]
        peer_wall = {p: peer_rest + peer["read_s"] + peer["transfer_s"] + peer["mesh_s"] * cores_run / p for p in CORES}
        rows.append({"file": name, "size_bytes": r["size_bytes"], "measured_wall": r["cadclash"]["wall_s"],
                     "measured_import": r["cadclash"]["import_s"], "one_thread_import": one_import,
                     "one_thread_wall": (r.get("cadclash_one_thread") or {}).get("wall_s"),
                     "parts": parts, "by_bytes": by_bytes, "by_cost": by_cost, "peer": peer_wall})
    with open(os.path.join(out, "core_model.json"), "w") as j:
        json.dump({"cores_run": cores_run, "commit": bench["commit"], "files": rows}, j, indent=1)
    if not rows:
        return
    with open(os.path.join(out, "results.md"), "a") as md:
        md.write("\n#### A model of more cores\n\n")
        md.write(f"Predicted from the median {cores_run}-core run's measured costs (scripts/import_core_model.py: each "
                 "piece's CPU seconds in its worker, shared out over P workers by weight as cadclash shares them; each "
                 "part's check-and-heal seconds dealt as OpenMP's dynamic schedule deals them; the query by Amdahl's "
                 "law from its 1- and 2-thread times; the rest serial as measured). Plain OCCT: read and transfer "
                 "serial, its meshing perfectly parallel. The model at the run's own cores is the measured run by "
                 "construction, where the measured pieces' window or heal took longer than the model (forks, pipes, "
                 "the other processes on the machine: that excess is kept at every P). P = 1 sums every cost "
                 "(cadclash on one thread reads the file whole: measured in the table above). Import efficiency: "
                 "the measured 1-thread run's import over (P x the modelled import).\n\n")
        md.write("| file | P | cadclash wall s (model) | import s | pieces window s | heal s | query s | "
                 "import efficiency | pieces shared by cost: wall s | plain OCCT wall s (model) | OCCT / cadclash |\n")
        md.write("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n")
        for row in rows:
            for p in CORES:
                b, c = row["by_bytes"][p], row["by_cost"][p]
                eff = f"{100 * row['one_thread_import'] / (p * b['import']):.0f} %" if row["one_thread_import"] else "–"
                md.write(f"| {row['file']} | {p} | {b['wall']:.2f} | {b['import']:.2f} | {b['window']:.2f} | "
                         f"{b['heal']:.2f} | {b['query']:.2f} | {eff} | {c['wall']:.2f} | {row['peer'][p]:.2f} | "
                         f"{row['peer'][p] / b['wall']:.2f} |\n")
        md.write("\nWhat bounds it (seconds, measured):\n\n")
        md.write("| file | pieces | pieces' CPU | largest piece | main parse | split | after the pieces (serial) | "
                 "parts' heal CPU | largest part's heal | query serial / parallel | rest of the process |\n")
        md.write("|---|---:|---:|---:|---:|---:|---:|---:|---:|---|---:|\n")
        for row in rows:
            q = row["parts"]
            md.write(f"| {row['file']} | {q['pieces']} | {q['pieces_cpu']:.2f} | {q['largest_piece']:.2f} | "
                     f"{q['main_parse']:.2f} | {q['split']:.2f} | {q['after']:.2f} | {q['heal_cpu']:.2f} | "
                     f"{q['largest_part_heal']:.2f} | {q['query_serial']:.2f} / {q['query_parallel']:.2f} | "
                     f"{q['rest']:.2f} |\n")


if __name__ == "__main__":
    main()
