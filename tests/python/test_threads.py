"""Queries release the GIL: other Python threads run while check() is busy, and concurrent queries
on one model give the serial answers. load() and Model.tessellate() run on the threads asked."""
import os
import threading

import numpy as np
import pytest

import cadclash


def test_other_python_thread_runs_during_check(as1):
    # The watcher counts its own loop iterations that happen while the scene reports a running
    # query. With the GIL held through check() the watcher could never run then: the count would
    # stay 0 however many queries ran. One as1 query (milliseconds) normally suffices.
    scene = cadclash.Scene(as1)
    stop = threading.Event()
    seen_running = [0]

    def watcher():
        while not stop.is_set():
            if scene.running:
                seen_running[0] += 1

    t = threading.Thread(target=watcher)
    t.start()
    try:
        report = None
        for _ in range(50):
            report = scene.check(threads=1)
            if seen_running[0] > 0:
                break
    finally:
        stop.set()
        t.join()
    assert seen_running[0] > 0
    assert not scene.running
    assert len(report) > 0


def test_concurrent_checks_on_one_model_match_serial(as1_path):
    model = cadclash.load(as1_path, lazy=True)  # concurrent queries also tessellate into the model
    scenes = [cadclash.Scene(model), cadclash.Scene(model, select_a="/as1/ROD-ASSEMBLY")]
    results = [None, None]

    def run(k):
        results[k] = scenes[k].check(tolerance=0.01)

    threads = [threading.Thread(target=run, args=(k,)) for k in range(2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    serial = [cadclash.Scene(model).check(tolerance=0.01),
              cadclash.Scene(model, select_a="/as1/ROD-ASSEMBLY").check(tolerance=0.01)]
    assert [r.pairs for r in results] == [r.pairs for r in serial]
    assert len(results[0]) > len(results[1]) > 0


# Threads a fresh process has before and after loading `files` (and tessellating, for lazy loads)
# with `threads`: OpenMP's, TBB's and OCCT's pools keep their threads once started, so the count
# after shows how many the work ran on.
_COUNT_THREADS = """
import os, sys
import cadclash
def live():
    return len(os.listdir("/proc/self/task"))
threads, lazy, files = int(sys.argv[1]), sys.argv[2] == "lazy", sys.argv[3:]
before = live()
model = cadclash.load(files, threads=threads, lazy=lazy)
if lazy:
    assert model.triangle_count == 0
    model.tessellate(threads=threads)
print(before, live(), model.triangle_count)
"""


def _threads_of_load(threads, lazy, files):
    import subprocess
    import sys
    proc = subprocess.run([sys.executable, "-c", _COUNT_THREADS, str(threads), "lazy" if lazy else "eager",
                           *map(str, files)], capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr
    before, after, triangles = map(int, proc.stdout.split())
    return after - before, triangles


@pytest.fixture(scope="module")
def two_files(as1_path, data_dir):
    second = data_dir / "external" / "step_boundary_colors.stp"
    if not second.is_file():
        pytest.skip(f"{second} is missing (scripts/setup.sh fetches data/external)")
    return [as1_path, second]


@pytest.mark.parametrize("lazy", [False, True])
@pytest.mark.parametrize("nfiles", [1, 2])  # one file: its parts meshed at once; two: files read at once
def test_load_and_tessellate_hold_to_the_threads_asked(two_files, lazy, nfiles):
    files = two_files[:nfiles]
    started_one, triangles_one = _threads_of_load(1, lazy, files)
    assert started_one == 0
    if os.cpu_count() >= 2:
        started_two, triangles_two = _threads_of_load(2, lazy, files)
        assert started_two >= 1  # the count sees threads when the work has them
        assert triangles_two == triangles_one


def test_load_threads_give_the_same_model(two_files):
    files = two_files
    one, every = cadclash.load(files, threads=1), cadclash.load(files, threads=0)
    assert len(one.surfaces) == len(every.surfaces) > 0
    for a, b in zip(one.surfaces, every.surfaces):
        assert np.array_equal(a.vertices, b.vertices) and np.array_equal(a.triangles, b.triangles)
    with pytest.raises(ValueError, match="threads"):
        cadclash.load(files, threads=-1)
    with pytest.raises(ValueError, match="threads"):
        one.tessellate(threads=-1)
