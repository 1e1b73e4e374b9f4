"""The GIL is released while Rust works: a sweep on one thread does not block another."""

import threading
import time

import hdi_tribology as hdi


def test_sweep_on_a_thread_does_not_block_python(paper_scene):
    done = threading.Event()
    result = {}

    def work():
        # a Scene, not a Model: the model build runs without the GIL too
        result["rows"] = hdi.ac_sweep(paper_scene, [0.1 * i for i in range(12)], threads=1)
        done.set()

    ticks = []
    t0 = time.perf_counter()
    worker = threading.Thread(target=work)
    worker.start()
    while not done.is_set():
        ticks.append(time.perf_counter())
        time.sleep(0.002)
    worker.join()
    elapsed = time.perf_counter() - t0
    assert len(result["rows"]) == 12
    gaps = [b - a for a, b in zip([t0] + ticks, ticks)]
    # Holding the GIL would stop this loop for the whole sweep (a single gap ~ elapsed); released,
    # it ticks every few ms throughout (allow for a loaded machine, not for a blocked one).
    assert elapsed > 0.1, f"sweep too short to tell ({elapsed:.3f} s)"
    assert len(ticks) > 10
    assert max(gaps) < 0.5 * elapsed, (max(gaps), elapsed)
