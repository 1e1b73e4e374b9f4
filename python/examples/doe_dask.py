"""A design of experiments on hdi_tribology, serially and on a Dask cluster, with the results
checked identical.

The design varies the surface roughness (rms height and peak-height scale together), the
Hamaker constant and the AC amplitude: 10 x 10 x 10 = 1000 scenes by default. Scenes that share
roughness and Hamaker constant share one built model (force tables), so one task is one
(roughness, Hamaker) pair: build the model, then one cycle per AC amplitude (`ac_sweep`, on
one thread inside the task). Every scene's touchdown, take-off, hysteresis and temperature rise
is written to a CSV; a scene whose cycle fails keeps its error message instead of numbers.

    pip install "dask[distributed]"          # besides hdi_tribology itself
    python python/examples/doe_dask.py                      # LocalCluster on every core
    python python/examples/doe_dask.py --workers 2 --grid 10 10 10
    python python/examples/doe_dask.py --scheduler tcp://10.0.0.5:8786 --skip-serial

With `--scheduler`, the same tasks go to a running multi-machine cluster (start it with
`dask scheduler` on one machine and `dask worker tcp://SCHEDULER:8786 --nthreads 1
--nworkers N` on each, every machine having hdi_tribology and dask installed).

It prints the wall time and throughput of each way of running, against a baseline measured in
the same run: the same tasks as Rust on every core of this machine (one Python thread per core,
the GIL released inside each task).
"""

import argparse
import csv
import os
import pathlib
import time
from concurrent.futures import ThreadPoolExecutor

import numpy as np

import hdi_tribology as hdi

FIELDS = ["height_sigma_nm", "hamaker_j", "v_ac_v", "touchdown_power_w", "takeoff_power_w",
          "hysteresis_w", "mean_temperature_rise_k", "steps", "status"]


def design(n_sigma, n_hamaker, n_ac):
    """The grid: (roughness in nm, Hamaker constant in J) pairs, and the AC amplitudes (V)."""
    sigmas = np.round(np.linspace(0.5, 0.9, n_sigma), 6).tolist()
    hamakers = [float(f"{a:.6g}e-19") for a in np.linspace(0.6, 1.5, n_hamaker)]
    amplitudes = np.round(np.linspace(0.0, 0.9, n_ac), 6).tolist()
    return [(s, a) for s in sigmas for a in hamakers], amplitudes


def run_group(sigma_nm, hamaker_j, amplitudes):
    """One task: the scenes of one (roughness, Hamaker constant) pair, one row per amplitude."""
    base = hdi.Scene.paper()
    try:
        scene = base.with_values({
            "surface.height_sigma_nm": sigma_nm,
            "surface.peaks.sigma_nm": sigma_nm,
            "intermolecular.hamaker_attractive_j": hamaker_j,
        })
        cycles = hdi.ac_sweep(hdi.Model(scene), amplitudes, threads=1)
    except hdi.HdiError as e:
        return [(sigma_nm, hamaker_j, v, None, None, None, None, 0, f"failed: {e}")
                for v in amplitudes]
    rows = []
    for c in cycles:
        # the crate's flags: no_touchdown, no_takeoff, negative_hysteresis (not a valid result)
        status = " ".join(c.flags) if c.flags else "ok"
        rows.append((sigma_nm, hamaker_j, c.v_ac_v,
                     c.touchdown.power_w if c.touchdown else None,
                     c.takeoff.power_w if c.takeoff else None,
                     c.hysteresis_w, c.mean_temperature_rise_k, c.steps, status))
    return rows


def run_serial(groups, amplitudes):
    return [run_group(s, a, amplitudes) for s, a in groups]


def run_threads(groups, amplitudes, n):
    """The baseline: the same tasks as Rust on n cores, one Python thread each (GIL released)."""
    with ThreadPoolExecutor(n) as pool:
        return list(pool.map(lambda g: run_group(g[0], g[1], amplitudes), groups))


def run_dask(client, groups, amplitudes):
    futures = client.map(run_group, [g[0] for g in groups], [g[1] for g in groups],
                         amplitudes=amplitudes, pure=False)
    return client.gather(futures)


def flat(results):
    return [row for group in results for row in group]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--grid", type=int, nargs=3, default=[10, 10, 10],
                    metavar=("N_SIGMA", "N_HAMAKER", "N_AC"))
    ap.add_argument("--workers", type=int, default=os.cpu_count(),
                    help="LocalCluster worker processes (one thread each)")
    ap.add_argument("--scheduler", help="address of a running Dask scheduler instead of a "
                    "LocalCluster, e.g. tcp://10.0.0.5:8786")
    ap.add_argument("--skip-serial", action="store_true",
                    help="run only on Dask (no serial run, no comparison)")
    ap.add_argument("--out", default="out/doe/results.csv")
    args = ap.parse_args()

    from dask.distributed import Client, LocalCluster

    groups, amplitudes = design(*args.grid)
    n_scenes = len(groups) * len(amplitudes)
    print(f"design: {len(groups)} (roughness, Hamaker) pairs x {len(amplitudes)} AC amplitudes "
          f"= {n_scenes} scenes")
    timings = {}

    if not args.skip_serial:
        t = time.perf_counter()
        serial = run_serial(groups, amplitudes)
        timings["serial, 1 core"] = time.perf_counter() - t
        t = time.perf_counter()
        threaded = run_threads(groups, amplitudes, args.workers)
        timings[f"baseline: Rust on {args.workers} cores"] = time.perf_counter() - t

    t = time.perf_counter()
    if args.scheduler:
        cluster = None
        client = Client(args.scheduler)
        where = f"Dask cluster at {args.scheduler}"
    else:
        cluster = LocalCluster(n_workers=args.workers, threads_per_worker=1, processes=True,
                               dashboard_address=None)
        client = Client(cluster)
        where = f"Dask LocalCluster, {args.workers} workers x 1 thread"
    client.wait_for_workers(1)
    startup = time.perf_counter() - t
    t = time.perf_counter()
    distributed = run_dask(client, groups, amplitudes)
    timings[where] = time.perf_counter() - t
    client.close()
    if cluster is not None:
        cluster.close()

    rows = flat(distributed)
    if not args.skip_serial:
        same = flat(serial) == rows == flat(threaded)
        print(f"serial, threaded and Dask results identical: {same}")
        if not same:
            raise SystemExit("results differ between serial and distributed runs")

    out = pathlib.Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    with out.open("w", newline="") as f:
        w = csv.writer(f)
        w.writerow(FIELDS)
        w.writerows(rows)
    ok = sum(r[-1] == "ok" for r in rows)
    print(f"{ok} of {n_scenes} scenes gave a valid hysteresis; the others say why in {out}")

    base = timings.get(f"baseline: Rust on {args.workers} cores")
    print(f"\n{'run':<48} {'wall s':>8} {'scenes/s':>9} {'ms/scene':>9} {'vs baseline':>11}")
    for name, s in timings.items():
        ratio = f"{base / s:.2f}" if base else "-"
        print(f"{name:<48} {s:8.2f} {n_scenes / s:9.1f} {1e3 * s / n_scenes:9.2f} {ratio:>11}")
    print(f"(Dask start-up, not counted above: {startup:.1f} s)")


if __name__ == "__main__":
    main()
