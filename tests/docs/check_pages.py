#!/usr/bin/env python3
"""Keeps the README and docs/ honest (CTest: docs_pages): every relative link of README.md and
docs/*.md points to a file that exists, and its #anchor to a heading of that page (GitHub's slugs);
every `cadclash SUBCOMMAND ... --switch` line of the README's and docs/cli.md's sh blocks names a
subcommand and switches that `cadclash SUBCOMMAND --help` lists. Prints each problem; exit 1 if any.
    check_pages.py CADCLASH_EXE SOURCE_DIR
"""
import glob
import os
import re
import subprocess
import sys

exe, root = sys.argv[1:3]
pages = [os.path.join(root, "README.md")] + sorted(glob.glob(os.path.join(root, "docs", "*.md")))
problems = []


def slug(heading):
    # GitHub: lower case, drop everything but letters, digits, spaces, hyphens and underscores,
    # spaces to hyphens.
    s = re.sub(r"[^\w\- ]", "", heading.strip().lower())
    return s.replace(" ", "-")


def anchors(path):
    out, code = set(), False
    for line in open(path, encoding="utf-8"):
        if line.startswith("```"):
            code = not code
        elif not code and line.startswith("#"):
            out.add(slug(line.lstrip("#")))
    return out


def outside_code(text):
    return re.sub(r"```.*?```", "", text, flags=re.S)


for page in pages:
    text = outside_code(open(page, encoding="utf-8").read())
    for target in re.findall(r"\]\(([^)\s]+)\)", text):
        if re.match(r"[a-z]+:", target):
            continue  # http(s), mailto
        file, _, anchor = target.partition("#")
        path = os.path.normpath(os.path.join(os.path.dirname(page), file)) if file else page
        name = os.path.relpath(page, root)
        if not os.path.exists(path):
            problems.append(f"{name}: link to missing {target}")
        elif anchor and path.endswith(".md") and anchor not in anchors(path):
            problems.append(f"{name}: link to missing heading {target}")

helps = {}


def help_of(sub):
    if sub not in helps:
        r = subprocess.run([exe, sub, "--help"], capture_output=True, text=True)
        helps[sub] = r.stdout if r.returncode == 0 else None
    return helps[sub]


for page in (os.path.join(root, "README.md"), os.path.join(root, "docs", "cli.md")):
    text = open(page, encoding="utf-8").read()
    for block in re.findall(r"```sh\n(.*?)```", text, flags=re.S):
        for line in block.splitlines():
            command = line.split("#", 1)[0]
            m = re.search(r"\bcadclash\s+([a-z]+)\b(.*)", command)
            if not m:
                continue
            sub, rest = m.group(1), m.group(2)
            h = help_of(sub)
            name = os.path.relpath(page, root)
            if h is None:
                problems.append(f"{name}: `cadclash {sub}` is not a subcommand ({line.strip()})")
                continue
            for switch in re.findall(r"(?<![\w-])(--[a-z][a-z-]*)", rest):
                if not re.search(re.escape(switch) + r"\b", h):
                    problems.append(f"{name}: `cadclash {sub} --help` lists no {switch} ({line.strip()})")

for p in problems:
    print(p)
print(f"checked {len(pages)} pages: {len(problems)} problems")
sys.exit(1 if problems else 0)
