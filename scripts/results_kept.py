#!/usr/bin/env python3
"""The tables docs/results.md takes from benchmarks that scripts/results.sh does not run
(scripts/import_peer_bench.sh, scripts/import_cache_bench.sh): on a fresh clone their outputs in
out/ are missing, and the page would lose the tables they last measured. This puts each missing
output back from the page as it stands (the block between the template's lines around its
placeholder, links as the bench writes them), so the page keeps the last measured tables, each
with the commit and date it names, until the bench runs again. Outputs already there are left as
they are. Prints what it put back.

    python3 scripts/results_kept.py ROOT
"""
import os
import re
import shutil
import sys


def block(page, template, placeholder):
    """The page's text where the template has `placeholder`, or None."""
    lines = template.split("\n")
    at = lines.index(placeholder)
    before = next(l for l in reversed(lines[:at]) if l.strip())
    after = next(l for l in lines[at + 1:] if l.strip())
    start = page.find("\n" + before + "\n")
    if start < 0:
        return None
    start += len(before) + 2
    end = page.find("\n" + after + "\n", start)
    if end < 0:
        return None
    text = page[start:end].strip("\n")
    if not text or text.startswith("_No run of"):
        return None
    return re.sub(r"\]\(results/([^/():]+\.(svg|png))\)", r"](\1)", text) + "\n"


def put(root, path, text, done):
    if os.path.exists(path) or text is None:
        return
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path, "w") as f:
        f.write(text)
    done.append(os.path.relpath(path, root))


def main():
    root = sys.argv[1]
    page_path = os.path.join(root, "docs", "results.md")
    if not os.path.exists(page_path):
        return
    page = open(page_path).read()
    template = open(os.path.join(root, "docs", "results", "template.md")).read()
    out = os.path.join(root, "out")
    done = []
    peer = block(page, template, "@IMPORT_PEER@")
    peer_dir = os.path.join(out, "import_peer_bench")
    if peer and not os.path.exists(os.path.join(peer_dir, "results.md")):
        svg = os.path.join(root, "docs", "results", "import_time.svg")
        if os.path.exists(svg):
            os.makedirs(peer_dir, exist_ok=True)
            shutil.copy(svg, os.path.join(peer_dir, "import_time.svg"))
        put(root, os.path.join(peer_dir, "results.md"), peer, done)
    cache = block(page, template, "@IMPORT_CACHE@")
    if cache:
        # One table per board, each opening with its own heading line; the 174 MB board's is the
        # second output (IMPORT_CACHE_BENCH_OUT=out/import_cache_bench_174).
        tables = re.split(r"\n(?=Import cache on re-runs of )", cache)
        for text in tables:
            name = "import_cache_bench_174" if text.startswith("Import cache on re-runs of board-150mb") else "import_cache_bench"
            put(root, os.path.join(out, name, "results.md"), text.strip("\n") + "\n", done)
    for d in done:
        print(f"results: kept the page's last table as {d} (its bench did not run in this tree)")


if __name__ == "__main__":
    main()
