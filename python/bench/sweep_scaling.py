#!/usr/bin/env python3
"""appell.sweep on 2 cores: serial, 2 threads, 2 processes and a 2-worker Dask
LocalCluster (127.0.0.1), on three workloads — 200 rolling-disk runs (speeds
1…3 m/s, the scene's dopri5 at tol 1e-10, 2 s each), 200 linearizations
of the steadily rolling disk (tests/data/linearize/disk_chain.urdf, spin
1…6 rad/s) and 200 linearizations of the Whipple bicycle
(examples/bicycle, forward speed 3…7 m/s). --repeat rounds, each running
every executor once in turn (a virtual machine's speed drifts by tens of
per cent within seconds as its host gets busy: interleaving puts the drift
on all executors alike); per executor the median wall time, the speed-up
(the median over rounds of serial / its wall in the same round), and the
per-case overhead:

    overhead = (workers × wall − Σ the cases' own wall times) / cases,

the time a worker spends per case on anything but the case (shipping,
scheduling, gathering, idling at the end), and CPU/wall, the cores this
process used (serial and threads; 2 threads on 2 free cores give about 2 —
less says the machine did not give them; processes and Dask work in other
processes, so theirs is the parent's small share). The process pool and the
cluster start once (their start-up printed apart) and run a warm-up of
one-case batches that loads the scene in each worker, as a user running many sweeps
keeps them; "dask-cold" (not run unless named in --executors) is
executor="dask", a LocalCluster started and closed by each sweep, its
start-up and teardown inside the time. Each sweep is checked equal to
the serial one bit for bit. Not a test: the figures depend on the machine
and its load, so the load average is printed before and after each
workload (python/bench/results.md records runs with it).

    PYTHONPATH=build/python /usr/bin/python3 python/bench/sweep_scaling.py

(--workloads disk-runs,bicycle picks some; --cases, --repeat, --workers,
--batch-size; --executors serial,threads,processes,dask,dask-cold.)
"""

import argparse
import concurrent.futures
import contextlib
import multiprocessing
import os
import pathlib
import statistics
import time

import numpy as np

import appell

ROOT = pathlib.Path(__file__).resolve().parents[2]
DISK = ROOT / "examples/rolling_disk/rolling_disk.urdf"
CHAIN = ROOT / "tests/data/linearize/disk_chain.urdf"
BIKE = ROOT / "examples/bicycle/bicycle.urdf"


def workloads(cases):
    return {
        "disk-runs": dict(scene=DISK, parameters={"speed": np.linspace(1.0, 3.0, cases)}, duration=2.0),
        "disk-linearizations": dict(scene=CHAIN, parameters={"spin.velocity": np.linspace(1.0, 6.0, cases)},
                                    analysis="linearize", cyclic=["plane.x", "plane.y", "plane.theta", "spin"]),
        "bicycle": dict(scene=BIKE, parameters={"plane.vx": np.linspace(3.0, 7.0, cases)}, analysis="linearize",
                        cyclic=["plane.x", "plane.y", "plane.theta", "rear_spin", "front_spin"]),
    }


def same(a, b):
    keys = ("q", "v", "eigenvalues", "max_energy_deviation", "friction_work", "max_real")
    return all(np.array_equal(a[k], b[k], equal_nan=True) for k in keys if k in a)


def warm_up(work, executor, workers):
    """Batches of one case, so that every worker loads the scene (not for
    "dask": its cluster is started and closed by each sweep)."""
    if executor != "dask":
        appell.sweep(**dict(work, parameters={k: v[: 4 * workers] for k, v in work["parameters"].items()}),
                     executor=executor, workers=workers, batch_size=1)


def one_sweep(work, executor, workers, batch_size):
    """Wall time, overhead per case, CPU/wall of this process, the result."""
    start, cpu = time.perf_counter(), os.times()
    r = appell.sweep(executor=executor, workers=workers, batch_size=batch_size, **work)
    wall = time.perf_counter() - start
    used = os.times()
    n = 1 if executor == "serial" else workers
    return (wall, (n * wall - r["wall_seconds"].sum()) / len(r),
            (used.user + used.system - cpu.user - cpu.system) / wall, r)


def measure(work, pools, names, workers, repeat, batch_size):
    """`repeat` rounds, each running every executor once in turn, so that a
    drift of the machine's speed (a virtual machine's host is busy or not)
    falls on all of them alike. Per executor: the median wall, overhead and
    CPU/wall, and the speed-up as the median over rounds of serial wall /
    its wall in the same round. Every result checked against the serial one."""
    for name in names:
        warm_up(work, pools[name], workers)
    samples = {name: [] for name in names}
    reference = None
    for _ in range(repeat):
        for name in names:
            wall, overhead, cpu, r = one_sweep(work, pools[name], workers, batch_size)
            if name == "serial":
                reference = r
            elif reference is not None and not same(r, reference):
                raise SystemExit(f"{name}: results differ from the serial sweep")
            samples[name].append((wall, overhead, cpu))
    out = {}
    for name in names:
        walls, overheads, cpus = zip(*samples[name])
        ratios = ([s[0] / w for s, w in zip(samples["serial"], walls)] if "serial" in samples else [])
        out[name] = (statistics.median(walls), statistics.median(overheads), statistics.median(cpus),
                     statistics.median(ratios) if ratios else None)
    return out


def empty_task(k):
    return k


def dask_round_trip(client, tasks):
    """The least a Dask sweep costs: `tasks` tasks that do nothing, submitted
    by one client.map and gathered — the messages client → scheduler →
    workers → scheduler → client and the gather, each stream batching its
    messages (2–10 ms intervals in distributed 2022.12)."""
    times = []
    for _ in range(21):
        start = time.perf_counter()
        client.gather(client.map(empty_task, range(tasks), pure=False))
        times.append(time.perf_counter() - start)
    return statistics.median(times)


def cli_sweep(appell_cli, work, workers, repeat):
    """The same workload through `appell sweep` on 1 and on `workers` threads;
    the tables checked byte for byte equal (--no-timing). Also a sweep of
    its first case alone: the command's fixed cost (the process's start —
    mostly the dynamic loader's relocations —, the scene's loading, the
    table's writing), which no thread shares; the cases' own speed-up is
    that of the walls less it."""
    import subprocess

    (name, values), = work["parameters"].items()

    def command(count):
        c = [appell_cli, "sweep", str(work["scene"]), "--no-timing",
             "--vary", f"{name}={float(values[0])!r}:{float(values[-1])!r}:{count}"]
        if work.get("analysis") == "linearize":
            c += ["--analysis", "linearize", "--cyclic", ",".join(work["cyclic"])]
        if "duration" in work:
            c += ["--duration", repr(work["duration"])]
        return c

    def timed(c):
        start = time.perf_counter()
        out = subprocess.run(c, capture_output=True, check=True).stdout
        return out, time.perf_counter() - start

    tables, times = {}, {1: [], workers: [], "fixed": []}
    for _ in range(repeat):  # interleaved rounds, as measure()
        for jobs in (1, workers):
            tables[jobs], wall = timed(command(len(values)) + [f"-j{jobs}"])
            times[jobs].append(wall)
        times["fixed"].append(timed(command(1) + ["-j1"])[1])
    if tables[1] != tables[workers]:
        raise SystemExit("appell sweep: the tables of -j1 and -j%d differ" % workers)
    walls = {k: statistics.median(v) for k, v in times.items()}
    fixed = walls["fixed"]
    cases = (walls[1] - fixed) / (walls[workers] - fixed)
    print(f"{'appell -j1':>10} {walls[1]:9.3f}   (one case alone: {fixed:.3f} s, the fixed cost)")
    ratio = statistics.median(a / b for a, b in zip(times[1], times[workers]))
    print(f"{f'appell -j{workers}':>10} {walls[workers]:9.3f} {ratio:8.2f}×  (same bytes as -j1; "
          f"the cases alone {cases:.2f}×)", flush=True)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cases", type=int, default=200)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--executors", default="serial,threads,processes,dask")
    ap.add_argument("--batch-size", type=int, help="cases per batch (default: appell.sweep's rule); "
                                                   "1 measures an executor's cost per batch")
    ap.add_argument("--workloads", default="disk-runs,disk-linearizations,bicycle")
    ap.add_argument("--cli", help="also time `appell sweep` of the same workloads, -j1 against -jWORKERS, "
                                  "with this appell binary (build/cli/appell)")
    args = ap.parse_args()
    print(f"load average before: {os.getloadavg()}")
    # Pools and the cluster start once, as a user running many sweeps keeps
    # them; their start-up is reported apart.
    pools = {"serial": "serial", "threads": "threads", "dask-cold": "dask"}
    names = args.executors.split(",")
    with contextlib.ExitStack() as stack:
        if "processes" in names:
            start = time.perf_counter()
            pools["processes"] = stack.enter_context(concurrent.futures.ProcessPoolExecutor(
                args.workers, mp_context=multiprocessing.get_context("spawn")))
            print(f"process pool: {time.perf_counter() - start:.2f} s to start")
        if "dask" in names:
            from distributed import Client, LocalCluster

            start = time.perf_counter()
            cluster = stack.enter_context(LocalCluster(n_workers=args.workers, threads_per_worker=1,
                                                       host="127.0.0.1", dashboard_address=None))
            pools["dask"] = stack.enter_context(Client(cluster))
            print(f"dask LocalCluster of {args.workers} workers: {time.perf_counter() - start:.2f} s to start")
            print(f"dask round trip of {args.workers} empty tasks (client.map, gather): "
                  f"{1e3 * dask_round_trip(pools['dask'], args.workers):.1f} ms, median of 21")
        chosen = args.workloads.split(",")
        for name, work in workloads(args.cases).items():
            if name not in chosen:
                continue
            print(f"\n{name}: {args.cases} cases, median of {args.repeat} interleaved rounds; "
                  f"load average {os.getloadavg()}")
            print(f"{'executor':>10} {'wall (s)':>9} {'speed-up':>9} {'overhead/case (ms)':>19} {'CPU/wall':>9}")
            for executor, (wall, overhead, cpu, speedup) in measure(work, pools, names, args.workers, args.repeat,
                                                                    args.batch_size).items():
                shown = f"{speedup:8.2f}×" if speedup else "        -"
                print(f"{executor:>10} {wall:9.3f} {shown} {1e3 * overhead:19.3f} {cpu:9.2f}", flush=True)
            if args.cli:
                cli_sweep(args.cli, work, args.workers, args.repeat)
            print(f"load average after {name}: {os.getloadavg()}")
    print(f"\nload average after: {os.getloadavg()}")


if __name__ == "__main__":
    main()
