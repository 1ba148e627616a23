"""Queries release the GIL: other Python threads run while check() is busy, and concurrent queries
on one model give the serial answers."""
import threading

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
