#!/usr/bin/env python3
"""Runs a command and writes the peak memory of its whole process tree, in KiB, to a file.

    python3 scripts/tree_memory.py OUT_FILE COMMAND [ARGS...]

The tree's memory is the sum over the command and every process it started (an isolated reader and
its workers) of their proportional set size (Pss in /proc/PID/smaps_rollup: a page that forked
processes share copy-on-write counts once over all of them), sampled every 100 ms. GNU time's %M is
the largest single process instead, which says nothing of workers that run at the same time. Exits
with the command's code; its stdout and stderr pass through.
"""
import os
import subprocess
import sys
import time


def children_of() -> dict:
    kids = {}
    for d in os.listdir("/proc"):
        if not d.isdigit():
            continue
        try:
            with open(f"/proc/{d}/stat") as f:
                ppid = int(f.read().rsplit(")", 1)[1].split()[1])
        except (OSError, IndexError, ValueError):
            continue
        kids.setdefault(ppid, []).append(int(d))
    return kids


def pss_kib(pid: int) -> int:
    try:
        with open(f"/proc/{pid}/smaps_rollup") as f:
            for line in f:
                if line.startswith("Pss:"):
                    return int(line.split()[1])
    except OSError:
        pass
    return 0


def tree_pss(root: int) -> int:
    kids = children_of()
    total, todo = 0, [root]
    while todo:
        pid = todo.pop()
        total += pss_kib(pid)
        todo.extend(kids.get(pid, []))
    return total


def main() -> int:
    out_file, command = sys.argv[1], sys.argv[2:]
    proc = subprocess.Popen(command)
    peak = 0
    while proc.poll() is None:
        peak = max(peak, tree_pss(proc.pid))
        time.sleep(0.1)
    with open(out_file, "w") as f:
        f.write(f"{peak}\n")
    return proc.returncode


if __name__ == "__main__":
    sys.exit(main())
