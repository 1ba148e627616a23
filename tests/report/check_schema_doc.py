"""docs/report-schema.md against what `cadclash check --json` writes (CTest: report_schema_doc).

Usage: check_schema_doc.py CADCLASH_EXE docs/report-schema.md DATA_DIR

Runs the CLI on real inputs (as1 by default and with --exact, twice through a --cache, OBJ boxes with
--all-triangles and --clearance, a --path trajectory, with and without timings, and as1 reviewed with
--baseline and --approvals), collects every key of every object
by where it occurs (top level, settings, pair, side, summary, counters, timings, step), and checks
both ways against the doc's sections: every written key is documented in its section, and every key
a section documents is written by some run. Every class, decided_by and kind value written is named
in the doc too (and so is every `cache` value written). A key the doc documents but no run writes must be added
to a run here (or listed in NOT_WRITTEN with the reason).
"""
import json
import pathlib
import re
import subprocess
import sys
import tempfile

# Section heading (as in the doc) -> where its keys occur in a report.
SECTIONS = {
    "Top level": "top",
    "`settings`": "settings",
    "Pair": "pair",
    "Side": "side",
    "Summary": "summary",
    "Counters": "counters",
    "Timings": "timings",
    "`model`": "model",
    "`model.bytes`": "model_bytes",
    "Step (with `--path`)": "step",
    "Clash": "clash",
    "ClashSide": "clash_side",
    "ClashSurfacePair": "clash_pair",
    "ClashInterference": "interference",
    "`review`": "review",
    "`review.summary`": "review_summary",
    "ApprovalUse": "approval_use",
    "Approval": "approval",
    "`import_timings`": "import_timings",
    "`import_timings.files[]`": "import_file",
    "`timeline` (with `--continuous`)": "timeline",
    "TimelinePair": "timeline_pair",
    "TimelineSurfacePair": "timeline_surface",
    "Span": "span",
}
# Documented keys no run here writes, with the reason. Keep empty when possible.
NOT_WRITTEN = {}


def documented(doc: str) -> dict:
    """Keys per context: the first column of a section's table rows, or for sections without a
    table the `identifier`s of their first paragraph."""
    out = {}
    parts = re.split(r"^#{2,3} (.+)$", doc, flags=re.M)
    for title, body in zip(parts[1::2], parts[2::2]):
        ctx = SECTIONS.get(title.strip())
        if ctx is None:
            continue
        rows = [l for l in body.splitlines() if l.startswith("| `")]
        if rows:
            keys = set()
            for row in rows:
                keys.update(re.findall(r"`([a-z_][a-z_0-9]*)`", row.split("|")[1]))
        else:
            paragraph = body.strip().split("\n\n")[0]
            keys = set(re.findall(r"`([a-z_]+)`", paragraph))
        out[ctx] = keys
    missing = set(SECTIONS.values()) - set(out)
    if missing:
        sys.exit(f"docs/report-schema.md: sections not found for {sorted(missing)}")
    return out


def collect(report: dict, seen: dict) -> None:
    def add(ctx, obj):
        seen.setdefault(ctx, set()).update(obj.keys())

    def query(obj):
        for p in obj.get("pairs", []):
            add("pair", p)
            seen.setdefault("values", set()).update({p["class"], p["decided_by"]})
            seen["values"].update(s["kind"] for s in (p["a"], p["b"]) if "kind" in s)
            add("side", p["a"])
            add("side", p["b"])
        if "summary" in obj:
            seen.setdefault("values", set()).update(obj["summary"]["decided_by"])
        for key in ("summary", "counters", "timings"):
            if key in obj:
                add(key, obj[key])
        if "model" in obj:
            add("model", obj["model"])
            add("model_bytes", obj["model"]["bytes"])
        for u in obj.get("unexamined_pairs", []):
            add("unexamined", u)

    add("top", report)
    add("settings", report["settings"])
    for c in report.get("clashes", []):
        add("clash", c)
        add("clash_side", c["a"])
        add("clash_side", c["b"])
        seen.setdefault("values", set()).add(c["status"])
        for p in c["surface_pairs"]:
            add("clash_pair", p)
        if c["interference"] is not None:
            add("interference", c["interference"])
    if "review" in report:
        add("review", report["review"])
        add("review_summary", report["review"]["summary"])
        for u in report["review"]["approvals"]:
            add("approval_use", u)
            add("approval", u["approval"])
            seen.setdefault("values", set()).add(u["state"])
    if "import_timings" in report:
        add("import_timings", report["import_timings"])
        for f in report["import_timings"]["files"]:
            add("import_file", f)
            seen.setdefault("values", set()).add(f["cache"])
    if "timeline" in report:
        add("timeline", report["timeline"])
        for p in report["timeline"]["pairs"]:
            add("timeline_pair", p)
            for sp in p["spans"]:
                add("span", sp)
            for s in p["surfaces"]:
                add("timeline_surface", s)
                add("side", s["a"])
                add("side", s["b"])
                for sp in s["spans"]:
                    add("span", sp)
    query(report)
    for s in report.get("steps", []):
        add("step", s)
        query(s)


def main() -> int:
    exe, doc_path, data = sys.argv[1], pathlib.Path(sys.argv[2]), pathlib.Path(sys.argv[3])
    boxes = [data / "collide" / f for f in ("box_a.obj", "box_overlap.obj", "box_near.obj")]
    as1 = data / "external" / "as1-tu-203.stp"
    if not as1.is_file():
        print(f"{as1} is missing (scripts/setup.sh fetches it)")
        return 1
    runs = [
        [as1, "--no-timings"],
        [as1, "--exact", "--cache", "CACHE"],
        [as1, "--exact", "--cache", "CACHE"],
        [*boxes, "--all-triangles", "--clearance", "1"],
        [boxes[0], boxes[2], "--path", data / "collide" / "path_ok.csv"],
        [boxes[0], boxes[2], "--path", data / "collide" / "path_ok.csv", "--continuous"],
        [boxes[0], boxes[2], "--path", data / "collide" / "path_pass.csv", "--continuous", "--clearance", "0.6"],
        [boxes[0], boxes[1], "--volume"],
    ]
    seen: dict = {}
    with tempfile.TemporaryDirectory() as tmp:
        outs = [pathlib.Path(tmp) / f"report{k}.json" for k in range(len(runs) + 1)]
        approvals = pathlib.Path(tmp) / "approvals.json"
        cache = pathlib.Path(tmp) / "cache"

        def review_run():
            # as1 reviewed against the boxes' report (every as1 clash new, the boxes' resolved), with
            # an id approval, a rule with every glob, classes and an expiry, and an expired one.
            first = json.loads(outs[0].read_text())["clashes"][0]["id"]
            common = {"reason": "designed", "by": "doc check", "date": "2026-01-01"}
            approvals.write_text(json.dumps({"schema": "cadclash-approvals", "version": 1, "approvals": [
                {"id": first, **common},
                {"a": "/as1/**", "b": "**/BOLT", "part_a": "*", "part_b": "bolt", "classes": ["touching"],
                 "expires": "2027-01-01", **common},
                {"id": "000000000000", "expires": "2020-01-01", **common}]}))
            return [as1, "--no-timings", "--baseline", outs[3], "--approvals", approvals, "--today", "2026-06-01",
                    "--group-by", "space"]

        for k, args in enumerate([*runs, None]):
            args = args if args is not None else review_run()
            args = [cache if a == "CACHE" else a for a in args]
            out = outs[k]
            proc = subprocess.run([exe, "check", *map(str, args), "--json", str(out)], capture_output=True, text=True)
            if proc.returncode not in (0, 3):
                print(f"cadclash check {' '.join(map(str, args))}: exit {proc.returncode}\n{proc.stderr}")
                return 1
            collect(json.loads(out.read_text()), seen)
    doc = documented(doc_path.read_text())
    errors = []
    for ctx, keys in sorted(doc.items()):
        written = seen.get(ctx, set())
        for key in sorted(written - keys):
            errors.append(f"{ctx}: `{key}` is written but not documented in its section")
        for key in sorted(keys - written - NOT_WRITTEN.get(ctx, set())):
            errors.append(f"{ctx}: `{key}` is documented but no run writes it")
    text = doc_path.read_text()
    for value in sorted(seen.get("values", set())):
        if f"`{value}`" not in text and f'`"{value}"`' not in text:
            errors.append(f"the value `{value}` (class, decided_by or kind) is written but not documented")
    if seen.get("unexamined", set()) - {"a", "b"}:
        errors.append("unexamined_pairs: keys other than a, b")
    for e in errors:
        print(f"{doc_path}: {e}")
    print(f"checked {sum(len(k) for k in doc.values())} documented keys against {len(runs) + 1} runs: "
          f"{len(errors)} problems")
    return 1 if errors else 0


if __name__ == "__main__":
    sys.exit(main())
