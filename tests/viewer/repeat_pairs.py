#!/usr/bin/env python3
"""Writes a copy of a cadclash HTML report whose pair list is repeated N times, for timing the pair
table, its filter and keys on tens of thousands of rows (docs/viewer.md) without a slow check: the
geometry stays that of the report. Usage: repeat_pairs.py REPORT.html N OUT.html"""
import json
import re
import sys

MARK = re.compile(r'(<script type="application/json" id="cadclash-data">)(.*?)(</script>)', re.S)


def main():
    if len(sys.argv) != 4:
        sys.exit(__doc__)
    report, n, out = sys.argv[1], int(sys.argv[2]), sys.argv[3]
    with open(report, encoding="utf-8") as f:
        html = f.read()
    m = MARK.search(html)
    if not m:
        sys.exit(f"{report}: no cadclash-data element; is it a `cadclash check --html` report?")
    data = json.loads(m.group(2))
    data["pairs"] = data["pairs"] * n
    # As the writer does: "<" only in strings, escaped so the data never closes the element.
    text = json.dumps(data, separators=(",", ":")).replace("<", "\\u003c")
    with open(out, "w", encoding="utf-8") as f:
        f.write(html[:m.start(2)] + text + html[m.end(2):])
    print(f"{out}: {len(data['pairs'])} pairs")


if __name__ == "__main__":
    main()
