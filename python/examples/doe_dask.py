"""A design of experiments on hdi_tribology, serially and on a Dask cluster, against a pure Rust
baseline of the same design, with the results checked identical bit for bit.

The design varies the surface roughness (rms height and peak-height scale together), the
Hamaker constant and the AC amplitude: 10 x 10 x 10 = 1000 scenes by default. Scenes that share
roughness and Hamaker constant share one built model (force tables), so one task is one
(roughness, Hamaker) pair: build the model, then one cycle per AC amplitude (`ac_sweep`, on
one thread inside the task). Every scene's touchdown, take-off, hysteresis and temperature rise
is written to a CSV; a scene whose cycle fails keeps its error message instead of numbers.

    pip install "dask[distributed]"          # besides hdi_tribology itself
    python python/examples/doe_dask.py                      # LocalCluster on every core
    python python/examples/doe_dask.py --workers 2 --grid 10 10 10 --rounds 2
    python python/examples/doe_dask.py --scheduler tcp://10.0.0.5:8786 --skip-serial --no-rust

With `--scheduler`, the same tasks go to a running multi-machine cluster (start it with
`dask scheduler` on one machine and `dask worker tcp://SCHEDULER:8786 --nthreads 1
--nworkers N` on each, every machine having hdi_tribology and dask installed).

The baseline is a Rust program with no Python in it, `examples/doe_baseline.rs` of the
repository: the same design and analysis on rayon with as many threads as there are Dask
workers (built with cargo unless `--rust-bin` names it). It writes its rows to a CSV, which is
compared with the Dask rows float by float (the bits, not a tolerance), and its wall time; the
Rust and Dask runs alternate `--rounds` times so that both see the same load. The serial run
(one process, one core) is compared too unless `--skip-serial`.
"""

import argparse
import csv
import json
import os
import pathlib
import statistics
import struct
import subprocess
import time

import hdi_tribology as hdi

REPO = pathlib.Path(__file__).resolve().parents[2]

FIELDS = ["height_sigma_nm", "hamaker_j", "v_ac_v", "touchdown_power_w", "takeoff_power_w",
          "hysteresis_w", "mean_temperature_rise_k", "steps", "status"]


def grid(start, stop, n):
    """`n` values from `start` to `stop`, rounded to 6 decimals (the rule of doe_baseline.rs)."""
    return [float(f"{start if n == 1 else start + (stop - start) * i / (n - 1):.6f}")
            for i in range(n)]


def design(n_sigma, n_hamaker, n_ac):
    """The grid: (roughness in nm, Hamaker constant in J) pairs, and the AC amplitudes (V)."""
    sigmas = grid(0.5, 0.9, n_sigma)
    hamakers = [float(f"{a:.6f}e-19") for a in grid(0.6, 1.5, n_hamaker)]
    return [(s, a) for s in sigmas for a in hamakers], grid(0.0, 0.9, n_ac)


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


def rust_binary(given):
    """The baseline program: `given`, or examples/doe_baseline built with cargo."""
    if given:
        return given
    out = subprocess.run(
        ["cargo", "build", "--release", "--example", "doe_baseline", "--message-format=json"],
        cwd=REPO, check=True, capture_output=True, text=True).stdout
    for line in out.splitlines():
        msg = json.loads(line)
        if msg.get("reason") == "compiler-artifact" and msg.get("executable") and \
                msg["target"]["name"] == "doe_baseline":
            return msg["executable"]
    raise SystemExit("cargo built no doe_baseline executable")


def run_rust(exe, grid_n, threads, out):
    """Runs the Rust baseline; returns its rows (as run_group gives them), its wall time and
    its CPU time (s)."""
    subprocess.run([exe, "--grid", *map(str, grid_n), "--threads", str(threads),
                    "--out", str(out)], check=True, stdout=subprocess.DEVNULL)
    figures = json.loads(out.with_suffix(".json").read_text())

    def opt(x):
        return float(x) if x != "" else None

    with out.open(newline="") as f:
        r = csv.reader(f)
        assert next(r) == FIELDS, "the baseline's CSV columns differ from FIELDS"
        rows = [(float(s), float(a), float(v), opt(td), opt(to), opt(h), opt(t), int(n), st)
                for s, a, v, td, to, h, t, n, st in r]
    return rows, figures["wall_s"], figures["cpu_s"]


def workers_cpu(client):
    """CPU time of every worker process so far (s), summed."""
    return sum(client.run(time.process_time).values())


def bits(row):
    """A row with every float replaced by its IEEE-754 bits, for a bit-for-bit comparison."""
    return tuple(struct.pack("<d", x).hex() if isinstance(x, float) else x for x in row)


def differences(a, b):
    """Indices of the rows of `a` and `b` that differ in any bit (or the length, if it does)."""
    if len(a) != len(b):
        return [f"{len(a)} rows against {len(b)}"]
    return [i for i, (x, y) in enumerate(zip(a, b)) if bits(x) != bits(y)]


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
                    help="LocalCluster worker processes (one thread each), and the threads of "
                    "the Rust baseline")
    ap.add_argument("--scheduler", help="address of a running Dask scheduler instead of a "
                    "LocalCluster, e.g. tcp://10.0.0.5:8786")
    ap.add_argument("--skip-serial", action="store_true", help="no serial Python run")
    ap.add_argument("--no-rust", action="store_true",
                    help="no Rust baseline (no comparison with Rust, no ratio)")
    ap.add_argument("--rust-bin", help="the doe_baseline executable (default: built with cargo)")
    ap.add_argument("--rounds", type=int, default=1,
                    help="Rust and Dask runs, alternating, to compare under the same load")
    ap.add_argument("--out", default="out/doe/results.csv")
    args = ap.parse_args()

    from dask.distributed import Client, LocalCluster

    groups, amplitudes = design(*args.grid)
    n_scenes = len(groups) * len(amplitudes)
    print(f"design: {len(groups)} (roughness, Hamaker) pairs x {len(amplitudes)} AC amplitudes "
          f"= {n_scenes} scenes")
    out = pathlib.Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    exe = None if args.no_rust else rust_binary(args.rust_bin)

    serial_s = serial_cpu = None
    if not args.skip_serial:
        t, c = time.perf_counter(), time.process_time()
        serial = flat(run_serial(groups, amplitudes))
        serial_s, serial_cpu = time.perf_counter() - t, time.process_time() - c

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
    client.wait_for_workers(args.workers if cluster is not None else 1)
    startup = time.perf_counter() - t
    # what the idle workers burn (event loop, heartbeats, profiler), per second of wall time
    c, t = workers_cpu(client), time.perf_counter()
    time.sleep(5)
    idle = (workers_cpu(client) - c) / (time.perf_counter() - t)

    rust_s, dask_s, rust_cpu, dask_cpu, rust_rows, rows = [], [], [], [], None, None
    for _ in range(args.rounds):
        if exe:
            rust_rows, s, c = run_rust(exe, args.grid, args.workers, out.with_name("rust.csv"))
            rust_s.append(s)
            rust_cpu.append(c)
        c = workers_cpu(client)
        t = time.perf_counter()
        rows = flat(run_dask(client, groups, amplitudes))
        dask_s.append(time.perf_counter() - t)
        dask_cpu.append(workers_cpu(client) - c)
    client.close()
    if cluster is not None:
        cluster.close()

    with out.open("w", newline="") as f:
        w = csv.writer(f)
        w.writerow(FIELDS)
        w.writerows(rows)
    ok = sum(r[-1] == "ok" for r in rows)
    print(f"{ok} of {n_scenes} scenes gave a valid hysteresis; the others say why in {out}")

    failed = False
    for name, other in [("serial Python", None if args.skip_serial else serial),
                        ("Rust baseline", rust_rows)]:
        if other is None:
            continue
        diff = differences(rows, other)
        print(f"Dask and {name} rows identical bit for bit: {not diff}"
              + (f" (differ: {diff[:5]})" if diff else ""))
        failed |= bool(diff)

    base = statistics.median(rust_s) if rust_s else None
    # wall: throughput on these cores under this run's load; CPU: what the scenes cost, which
    # the load of other processes on the machine does not inflate
    print(f"\n{'run':<52} {'wall s':>8} {'scenes/s':>9} {'vs Rust':>8} {'CPU ms/scene':>13}")
    table = []
    if serial_s is not None:
        table.append(("Python serial, 1 core", serial_s, serial_cpu))
    for i in range(len(dask_s)):
        if rust_s:
            table.append((f"Rust doe_baseline, {args.workers} threads (round {i + 1})",
                          rust_s[i], rust_cpu[i]))
        table.append((f"{where} (round {i + 1})", dask_s[i], dask_cpu[i]))
    for name, s, c in table:
        ratio = f"{base / s:.3f}" if base else "-"
        cpu = f"{1e3 * c / n_scenes:13.1f}" if c is not None else f"{'-':>13}"
        print(f"{name:<52} {s:8.2f} {n_scenes / s:9.2f} {ratio:>8} {cpu}")
    if rust_s:
        ratios = [r / d for r, d in zip(rust_s, dask_s)]
        cpu_ratios = [d / r for r, d in zip(rust_cpu, dask_cpu)]
        print(f"Dask throughput over Rust's (wall), per round: "
              f"{', '.join(f'{x:.3f}' for x in ratios)} (median {statistics.median(ratios):.3f})")
        print(f"Dask CPU per scene over Rust's, per round: "
              f"{', '.join(f'{x:.3f}' for x in cpu_ratios)} "
              f"(median {statistics.median(cpu_ratios):.3f})")
    print(f"(Dask start-up, not counted above: {startup:.1f} s; idle workers use "
          f"{idle:.3f} s of CPU per second of wall time, together)")
    if failed:
        raise SystemExit("results differ between the runs")


if __name__ == "__main__":
    main()
