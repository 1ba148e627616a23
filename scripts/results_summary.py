#!/usr/bin/env python3
"""The one-screen summary at the top of docs/results.md (issue 41): per area one row, cadclash's
figure beside its peers', each from this run's raw outputs in OUT (scripts/results.sh writes them)
and linking to the section that measures it. Writes Markdown on stdout.
    python3 scripts/results_summary.py OUT_DIR DATE COMMIT MACHINE
"""
import json
import os
import sys

out, date, commit, machine = sys.argv[1:5]


def load(name):
    path = os.path.join(out, name)
    return json.load(open(path)) if os.path.exists(path) else None


def ms(seconds):
    if seconds is None:
        return "–"
    return f"{seconds:.3g} s" if seconds >= 1.0 else f"{1e3 * seconds:.3g} ms"


rows = []
compare = load("compare.json")
if compare:
    def method(workload, prefix):
        for m in workload["methods"]:
            if m["name"].startswith(prefix) and not m.get("error"):
                return m
        return None

    for w in compare["workloads"]:
        if w["name"] not in ("as1-tu-203.stp, deflection 0.1 mm", 'as1 trajectory "withdraw", deflection 0.1 mm'):
            continue
        ours = method(w, "cadclash default")
        fast = method(w, "cadclash --fast")
        peers = [(label, method(w, prefix)) for label, prefix in
                 (("FCL OBBRSS", "FCL BVHModel<OBBRSS>"), ("CGAL", "CGAL box_intersection_d"),
                  ("OCCT proximity", "OCCT BRepExtrema_ShapeProximity, tolerance 0"))]
        # A path's time per step; slow peers run every stride-th step only (on_subset).
        steps = w.get("steps", 1)
        stride = w.get("subset", {}).get("step_stride", 1)

        def each(m):
            n = len(range(0, steps, stride)) if m.get("on_subset") else steps
            return m["median_seconds"] / n

        per = "per query" if steps <= 1 else f"per step of {steps}"
        peer_text = "; ".join(f"{label} {ms(each(m))}" for label, m in peers if m)
        rows.append((f"Query, {w['name']} ({compare['threads']} threads, {per})",
                     f"{ms(each(ours)) if ours else '–'} certified, {ms(each(fast)) if fast else '–'} --fast",
                     peer_text, "#side-by-side"))

    # Scale: the 10-million-triangle instanced scene, whole and on the peers' subset of pairs.
    for w in compare["workloads"]:
        if not w["name"].startswith("instanced scene"):
            continue
        whole, sub, fast = method(w, "cadclash default ("), method(w, "cadclash default [subset]"), method(w, "cadclash --fast")
        peers = [(label, method(w, prefix)) for label, prefix in
                 (("FCL OBBRSS", "FCL BVHModel<OBBRSS>"), ("CGAL", "CGAL box_intersection_d"),
                  ("OCCT proximity", "OCCT BRepExtrema_ShapeProximity, tolerance 0"))]
        if whole and sub:
            rows.append((f"Scale: {w['name']} ({compare['threads']} threads, one query)",
                         f"every pair {ms(whole['median_seconds'])} certified; the peers' subset of pairs "
                         f"{ms(sub['median_seconds'])} certified" + (f", {ms(fast['median_seconds'])} --fast" if fast else ""),
                         "on that subset: " + "; ".join(f"{label} {ms(m['median_seconds'])}" for label, m in peers if m),
                         "#side-by-side"))

scale = load("scale.json")
if scale:
    b = scale["bytes_scene"]
    rows.append((f"Memory: the collision model of {scale['instances']:,} instances, {scale['instance_triangles']:,} "
                 "instance triangles",
                 f"{b['total'] / 2**20:.2f} MiB ({b['total'] / scale['instance_triangles']:.2f} bytes per instance "
                 "triangle: parts shared by their instances)", None, "#scale-one-part-moving-through-a-large-scene"))

accuracy = load("accuracy.json")
if accuracy:
    def worst(mode):
        rs = [r for f in accuracy["files"] for r in f["rows"] if r["mode"] == mode]
        if not rs:
            return None
        return min(r["recall"] for r in rs), min(r["precision"] for r in rs), sum(1 for _ in rs)

    ours = worst("certified")
    peers = [(m, worst(m)) for m in ("fast", "occt-proximity")]
    if ours:
        rows.append(("Accuracy against exact B-rep truth (as1, as1 moved 0.05 mm; every deflection and tolerance)",
                     f"certified: recall ≥ {ours[0]:.4g}, precision ≥ {ours[1]:.4g} over {ours[2]} settings "
                     "(below 1 only where the truth's own OCCT distance misses a B-spline minimum)",
                     "; ".join(f"{m}: recall ≥ {p[0]:.4g}, precision ≥ {p[1]:.4g}" for m, p in peers if p),
                     "#accuracy-against-the-exact-geometry"))

band = os.path.join(out, "uncertainty")
sunk = [os.path.join(band, f"sunk-{m}.json") for m in ("auto", "fast")]
if all(os.path.exists(p) for p in sunk):
    cert, fast = (json.load(open(p)) for p in sunk)
    rows.append(("Real-part board, components sunk 0.025 mm, KiCad's declared 0.01 mm (2 threads)",
                 f"{cert['summary']['penetrating']} pairs proved penetrating, {cert['summary']['undecided']} undecided; "
                 f"query {ms(cert['timings']['total'])}, end to end {ms(cert['import_timings']['seconds'] + cert['timings']['total'])}",
                 f"--fast: {fast['summary']['penetrating']} penetrating (not certified); query {ms(fast['timings']['total'])}, "
                 f"end to end {ms(fast['import_timings']['seconds'] + fast['timings']['total'])}",
                 "#the-model-uncertainty-band-on-a-real-part-board"))

boards = os.path.join(out, "boards")
seated = [os.path.join(boards, f"board-40mb-{m}.json") for m in ("certified", "fast")]
if all(os.path.exists(p) for p in seated):
    cert, fast = (json.load(open(p)) for p in seated)
    def contacts(j):
        return j["summary"]["penetrating"] + j["summary"]["touching"]
    def e2e(j):
        return j["import_timings"]["seconds"] + j["timings"]["total"]
    rows.append(("Real-part 40 MB board, components 0.05 mm above it (2 threads)",
                 f"certified: {contacts(cert)} contacts, {cert['summary']['undecided']} undecided (every gap is 0.05 mm); "
                 f"query {ms(cert['timings']['total'])}, end to end {ms(e2e(cert))}",
                 f"--fast: {contacts(fast)} pairs called touching (its band, not the faces); query "
                 f"{ms(fast['timings']['total'])}, end to end {ms(e2e(fast))}",
                 "#certified-against---fast-on-real-part-boards"))

# Continuous motion (scripts/continuous_bench.sh's table): the as1 paths' continuous check beside the
# discrete check of the same steps and FCL's continuous collision, and what the dense exact reference
# found outside the spans on every path.
continuous = os.path.join(out, "continuous.md")
if os.path.exists(continuous):
    header, paths = None, {}
    for line in open(continuous):
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if "continuous / discrete" in cells:
            header = cells
        elif header and len(cells) == len(header) and cells[0] and not cells[0].startswith("---"):
            paths[cells[0]] = dict(zip(header, cells))
    shown = [paths[n] for n in ("unscrew-10", "withdraw-8") if n in paths]
    if shown:
        missed = sum(1 for r in paths.values() if r["missed: pairs / surface pairs"] != "0 / 0")
        ours = "; ".join(f"{r['path']}: {r['continuous ms']} ms, {r['continuous / discrete']} its discrete check "
                         f"({r['discrete ms (steps in contact)'].split()[0]} ms)" for r in shown)
        ours += (f"; contacts missed against the exact reference on {len(paths)} paths: "
                 + ("none" if missed == 0 else f"on {missed} paths (see the section)")
                 + " (tunnelling paths included, whose steps are all clear)")
        peers = "FCL continuous (conservative advancement, its triangles): " + "; ".join(
            f"{r['path']}: {r['FCL ms (queries)'].split()[0]} ms, found {r['FCL found / expected, extra, toc error; naive control'].split(',')[0]} "
            "stretches in contact" for r in shown)
        rows.append(("Continuous motion: certified contact between the steps of as1 paths (2 threads)", ours, peers,
                     "#continuous-motion-along-paths"))

print(f"**Summary** ({date}, commit {commit}, {machine}; the sections below say how each figure is measured)")
print()
print("| area | cadclash | peers | section |")
print("|---|---|---|---|")
for area, ours, peers, link in rows:
    print(f"| {area} | {ours} | {peers or '–'} | [details]({link}) |")
# The import comparison is measured by scripts/import_peer_bench.sh (~20 min), not by this run: its
# last table's 40 MB row, as the page shows it.
peer = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "out", "import_peer_bench", "results.md")
row = None
if os.path.exists(peer):
    header = None
    for line in open(peer):
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if "cadclash wall s" in cells:
            header = cells
        elif header and cells and cells[0] == "board-40mb.step" and len(cells) == len(header):
            row = dict(zip(header, cells))
link = "[details](#import-at-product-scale-kicad-boards-against-the-plain-occt-pipeline)"
if row:
    print(f"| Whole check of a 40 MB real-part STEP board against plain OCCT's read + transfer + mesh "
          f"(2 threads; scripts/import_peer_bench.sh, not this run) | {row['cadclash wall s']} s, RSS "
          f"{row['RSS MB cadclash']} MB | plain OCCT pipeline {row['peer wall s']} s, RSS {row['RSS MB peer']} MB | {link} |")
else:
    print("| Import of a large STEP file against plain OCCT (read + transfer + mesh) | see the section (measured by "
          f"scripts/import_peer_bench.sh, not by this run) | plain OCCT pipeline | {link} |")
