"""Benchmark: the Python overhead of one cycle call, against the Rust time of the same call.

    python python/examples/bench_overhead.py [REPEATS]

Each call's wall time seen from Python is compared with `Cycle.wall_seconds`, the time the Rust
simulation measured for itself inside the same call, so both come from the same run on the same
machine. The overhead is everything else: arguments, options, releasing the GIL, building the
result objects and copying the time series into numpy arrays. Also times `ac_sweep` on one
shared model (cycles per second on every core; the DoE baseline is examples/doe_baseline.rs).
"""

import statistics
import sys
import time

import hdi_tribology as hdi


def main():
    repeats = int(sys.argv[1]) if len(sys.argv) > 1 else 200
    model = hdi.Model(hdi.Scene.paper())
    print(f"{'call':<44} {'Python ms':>10} {'Rust ms':>9} {'overhead':>9}")
    for label, kwargs in [("simulate_cycle, series as numpy arrays", {}),
                          ("simulate_cycle, summary only", {"series": False}),
                          ("simulate_cycle at V_ac = 0.6 V, series", {"v_ac": 0.6})]:
        hdi.simulate_cycle(model, **kwargs)  # warm up
        py, rust = [], []
        for _ in range(repeats):
            t = time.perf_counter()
            r = hdi.simulate_cycle(model, **kwargs)
            py.append(time.perf_counter() - t)
            rust.append(r["cycle"].wall_seconds)
        # medians of the per-call differences: robust to the odd slow call on a shared machine
        over = statistics.median(p - r for p, r in zip(py, rust))
        rust_ms = 1e3 * statistics.median(rust)
        print(f"{label:<44} {1e3 * statistics.median(py):10.3f} {rust_ms:9.3f} "
              f"{100 * over / statistics.median(rust):8.2f}%")
    amplitudes = [0.1 * i for i in range(10)] * 4
    t = time.perf_counter()
    cycles = hdi.ac_sweep(model, amplitudes)
    wall = time.perf_counter() - t
    steps = sum(c.steps for c in cycles)
    print(f"ac_sweep, shared model, every core: {len(cycles)} cycles in {wall:.3f} s = "
          f"{len(cycles) / wall:.1f} cycles/s ({steps} steps)")
    t = time.perf_counter()
    hdi.Model(hdi.Scene.paper())
    print(f"building one model (force tables) from a scene: {time.perf_counter() - t:.3f} s")


if __name__ == "__main__":
    main()
