#!/usr/bin/env python3
"""docs/results.md is generated (CTest: docs_results_page): every line of docs/results/template.md
that is not a @PLACEHOLDER@ appears in the page, in order, with only generated text between, and
each placeholder's text is not empty; the summary opens the page. An edit by hand outside the
generated blocks, or a page not regenerated after the template changed, fails.
    check_results_page.py SOURCE_DIR
"""
import os
import re
import sys

root = sys.argv[1]
# Blank lines carry no content (generated blocks hold their own): compared without them.
template = [l for l in open(os.path.join(root, "docs", "results", "template.md"), encoding="utf-8").read().splitlines() if l.strip()]
page = [l for l in open(os.path.join(root, "docs", "results.md"), encoding="utf-8").read().splitlines() if l.strip()]
problems = []
i = 0  # next page line
for n, line in enumerate(template):
    if re.fullmatch(r"@[A-Z_]+@", line):
        # Generated text up to the template's next literal line.
        nxt = next((t for t in template[n + 1:] if not re.fullmatch(r"@[A-Z_]+@", t)), None)
        start = i
        while i < len(page) and (nxt is None or page[i] != nxt):
            i += 1
        if not any(l.strip() for l in page[start:i]):
            problems.append(f"{line} has no generated text in the page")
        if line == "@SUMMARY@" and not any(l.startswith("**Summary**") for l in page[start:i]):
            problems.append("the page does not open with the generated summary")
        continue
    if i >= len(page) or page[i] != line:
        problems.append(f"a template line is not where expected in docs/results.md: {line[:80]!r}")
        break
    i += 1
if not problems and i != len(page):
    problems.append(f"docs/results.md has {len(page) - i} lines past the template's end")
for p in problems:
    print(p)
print(f"checked docs/results.md against its template: {len(problems)} problems")
sys.exit(1 if problems else 0)
