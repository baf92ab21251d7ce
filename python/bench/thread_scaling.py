#!/usr/bin/env python3
"""Throughput of independent simulations on 1 and 2 Python threads.

Simulation.advance_to releases the GIL, so simulations of their own step in
parallel on threads. Each job simulates one rolling disk
(examples/rolling_disk) with RK4 at a fixed step; the same jobs run on one
thread, then split over two (concurrent.futures); the speed-up is the ratio
of the wall times, median of the repetitions. Not a test: the figure depends
on the machine and its load (python/bench/results.md records one).

    PYTHONPATH=build/python /usr/bin/python3 python/bench/thread_scaling.py
"""

import argparse
import concurrent.futures
import pathlib
import statistics
import time

import appell

DISK = pathlib.Path(__file__).resolve().parents[2] / "examples/rolling_disk/rolling_disk.urdf"


def job(scene, duration, dt):
    sim = appell.Simulation(scene, integrator="rk4", dt=dt)
    sim.advance_to(duration)
    return sim.counters["steps"]


def run(scene, threads, jobs, duration, dt):
    start = time.perf_counter()
    with concurrent.futures.ThreadPoolExecutor(max_workers=threads) as pool:
        steps = sum(pool.map(lambda _: job(scene, duration, dt), range(jobs)))
    return time.perf_counter() - start, steps


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--jobs", type=int, default=32, help="simulations per run (default 32)")
    ap.add_argument("--duration", type=float, default=1.0, help="simulated seconds each (default 1)")
    ap.add_argument("--dt", type=float, default=1e-4, help="RK4 step (default 1e-4)")
    ap.add_argument("--repeat", type=int, default=5, help="repetitions, median reported (default 5)")
    args = ap.parse_args()
    scene = appell.load_scene(DISK)
    run(scene, 2, 2, 0.01, args.dt)  # warm-up
    times = {1: [], 2: []}
    for _ in range(args.repeat):  # interleaved, so drifting load hits both alike
        for n in (1, 2):
            wall, steps = run(scene, n, args.jobs, args.duration, args.dt)
            times[n].append(wall)
    t1, t2 = statistics.median(times[1]), statistics.median(times[2])
    print(f"{args.jobs} rolling disks x {steps // args.jobs} RK4 steps, median of {args.repeat}")
    print(f"1 thread : {t1:.3f} s  ({steps / t1 / 1e3:.0f} k steps/s)")
    print(f"2 threads: {t2:.3f} s  ({steps / t2 / 1e3:.0f} k steps/s)")
    print(f"speed-up : {t1 / t2:.2f}x")


if __name__ == "__main__":
    main()
