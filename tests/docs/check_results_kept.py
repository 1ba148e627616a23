#!/usr/bin/env python3
"""scripts/results_kept.py (CTest: docs_results_kept): on a tree whose out/ lacks the import
benches' outputs, it puts back the page's last tables, and the page rendered from them (links made
as scripts/results.sh makes them) holds the same text where the template has @IMPORT_PEER@ and
@IMPORT_CACHE@; an output already there is left alone.
    check_results_kept.py SOURCE_DIR
"""
import os
import re
import shutil
import subprocess
import sys
import tempfile

root = sys.argv[1]
problems = []
with tempfile.TemporaryDirectory() as tmp:
    os.makedirs(os.path.join(tmp, "docs", "results"))
    shutil.copy(os.path.join(root, "docs", "results.md"), os.path.join(tmp, "docs", "results.md"))
    for name in ("template.md", "import_time.svg"):
        shutil.copy(os.path.join(root, "docs", "results", name), os.path.join(tmp, "docs", "results", name))
    # An output already there stays as it is.
    os.makedirs(os.path.join(tmp, "out", "import_cache_bench_174"))
    mine = os.path.join(tmp, "out", "import_cache_bench_174", "results.md")
    open(mine, "w").write("a later run\n")
    kept = os.path.join(root, "scripts", "results_kept.py")
    subprocess.run([sys.executable, kept, tmp], check=True, stdout=subprocess.DEVNULL)
    if open(mine).read() != "a later run\n":
        problems.append("an output already in out/ was overwritten")
    relink = lambda t: re.sub(r"\]\(([^/():]+\.(svg|png))\)", r"](results/\1)", t)
    page = open(os.path.join(root, "docs", "results.md")).read()
    peer = os.path.join(tmp, "out", "import_peer_bench", "results.md")
    cache = os.path.join(tmp, "out", "import_cache_bench", "results.md")
    for path in (peer, cache):
        if not os.path.exists(path):
            problems.append(f"not put back: {os.path.relpath(path, tmp)}")
        elif relink(open(path).read()).strip("\n") not in page:
            problems.append(f"{os.path.relpath(path, tmp)} is not the page's table")
    if os.path.exists(peer) and not os.path.exists(os.path.join(tmp, "out", "import_peer_bench", "import_time.svg")):
        problems.append("the import plot was not kept")
    if os.path.exists(peer) and "](results/" in open(peer).read():
        problems.append("the peer table's links are the page's, not the bench's")
    if os.path.exists(peer) and "| board-40mb.step |" not in open(peer).read():
        problems.append("the peer table lost its rows")
    # A second run puts nothing back.
    again = subprocess.run([sys.executable, kept, tmp], check=True, capture_output=True, text=True).stdout
    if again.strip():
        problems.append("a second run put back: " + again.strip())
for p in problems:
    print(p)
print(f"checked scripts/results_kept.py on the page: {len(problems)} problems")
sys.exit(1 if problems else 0)
