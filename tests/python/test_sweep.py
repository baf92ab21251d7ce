"""appell.sweep: every executor gives the numbers of the same cases run one by
one (appell.run / appell.linearize of the overridden scene) bit for bit and
in case order, however the cases are cut into batches; a Dask LocalCluster
of two worker processes on 127.0.0.1 included. A case that fails inside a
batch is its own row's error, the rest of its batch runs. Random draws are
reproducible from their seed and stay in their laws' support; a misspelt
parameter is an error before anything runs.
"""

import importlib
import math
import os
import subprocess

import numpy as np
import pytest

import appell
from conftest import example, SOURCE_DIR

DISK = example("rolling_disk/rolling_disk.urdf")
CHAIN = SOURCE_DIR / "tests/data/linearize/disk_chain.urdf"
CYCLIC = ["plane.x", "plane.y", "plane.theta", "spin"]
# Short RK4 runs: the cases differ in speed and in gravity's strength.
RUN = dict(duration=0.3, integrator="rk4", dt=2e-3)
GRID = {"speed": [1.0, 1.5, 2.25], "gravity": [(0, 0, -9.81), (0, 0, -1.62)]}

# Eight cases: batches of 1, 3 (3 + 3 + 2) and 8 cut them evenly, unevenly
# and not at all.
GRID8 = {"speed": [1.0, 1.5, 2.25, 3.0], "gravity": [(0, 0, -9.81), (0, 0, -1.62)]}
sweep_module = importlib.import_module("appell.sweep")

RUN_COLUMNS = ["time", "energy0", "energy", "impact_energy_loss", "friction_work", "joint_work",
               "support_work", "max_energy_deviation", "max_velocity_residual", "max_gap_residual"]


def serial_runs(cases):
    scene = appell.load_scene(DISK)
    return [appell.run(scene, case, **RUN) for case in cases]


def assert_equal_to_serial(result, runs):
    assert list(result["status"]) == ["ok"] * len(runs)
    for k, r in enumerate(runs):
        assert np.array_equal(result["q"][k], r.q) and np.array_equal(result["v"][k], r.v), k
        for name in RUN_COLUMNS:
            assert result[name][k] == getattr(r, name), (k, name)
        assert result["steps"][k] == r.steps
        assert result["events"][k] == sum(r.event_counts.values())


@pytest.mark.parametrize("executor", ["serial", "threads", "processes"])
def test_grid_equals_the_cases_run_one_by_one_bit_for_bit(executor):
    result = appell.sweep(DISK, GRID, executor=executor, workers=2, batch_size=2, **RUN)
    assert len(result) == 6 and result.parameters == ["speed", "gravity"]
    # The grid's order: the last name varies fastest.
    assert list(result.cases[1]) == [("speed", 1.0), ("gravity", (0, 0, -1.62))]
    assert np.array_equal(result["speed"], [1.0, 1.0, 1.5, 1.5, 2.25, 2.25])
    assert result["gravity"].shape == (6, 3)
    assert_equal_to_serial(result, serial_runs(result.cases))
    # Each case did what it says: the disk starts at its speed (body-frame vx).
    for k, case in enumerate(result.cases):
        scene, _ = appell.apply_overrides(appell.load_scene(DISK), case)
        assert scene.v0[3] == dict(case)["speed"]


@pytest.mark.parametrize("batch_size", [1, 3, 8, None])
@pytest.mark.parametrize("executor", ["threads", "processes"])
def test_every_cut_into_batches_gives_the_serial_numbers_in_case_order(executor, batch_size):
    # None: the pilot case runs here, the rest in batches by _batch_count.
    result = appell.sweep(DISK, GRID8, executor=executor, workers=2, batch_size=batch_size, **RUN)
    assert len(result) == 8
    assert np.array_equal(result["speed"], np.repeat(GRID8["speed"], 2))
    assert_equal_to_serial(result, serial_runs(result.cases))
    assert (result["wall_seconds"] > 0).all()


def test_batch_count_rule():
    count = sweep_module._batch_count
    dask, threads = sweep_module.MIN_BATCH_SECONDS["dask"], sweep_module.MIN_BATCH_SECONDS["threads"]
    assert (dask, threads) == (0.1, 0.005)
    # 200 bicycle linearizations (0.25 ms each) on 2 Dask workers: 50 ms of
    # work does not fill one 100 ms batch per worker — so one each.
    assert count(200, 2, 0.25e-3, dask) == 2
    # 200 disk runs (4.6 ms each): 920 ms, four batches per worker.
    assert count(200, 2, 4.6e-3, dask) == 8
    # Threads (5 ms batches) cut the bicycle's 50 ms into 8.
    assert count(200, 2, 0.25e-3, threads) == 8
    # Never more batches than cases, never fewer than one; a multiple of the workers between.
    assert count(3, 4, 1.0, dask) == 3
    assert count(1, 8, 1e-6, dask) == 1
    # 10⁵ of them on 100 workers: 25 s, two batches of 125 ms per worker;
    # 10⁴: 2.5 s, one of 25 ms per worker — every worker busy before 100 ms each.
    assert count(10**5, 100, 0.25e-3, dask) == 200
    assert count(10**4, 100, 0.25e-3, dask) == 100
    assert count(10**6, 100, 0.25e-3, dask) == 400
    # Strided batches: every case once, sizes within one, each batch a
    # sample of the whole range (the cost gradient of a grid shared alike).
    batches = sweep_module._strides(1, 200, 8)
    cases = sorted(k for b in batches for k in b)
    sizes = [len(b) for b in batches]
    assert cases == list(range(1, 200)) and max(sizes) - min(sizes) <= 1
    assert list(batches[0][:3]) == [1, 9, 17] and list(batches[-1][:2]) == [8, 16]


def test_a_case_that_fails_inside_a_batch_is_its_row_alone():
    cases = [[("speed", 1.0)], [("speed", math.nan)], [("speed", 2.0)], [("speed", 3.0)]]
    result = appell.sweep(DISK, cases=cases, executor="threads", workers=2, batch_size=2, **RUN)
    assert list(result["status"]) == ["ok", "error", "ok", "ok"]
    assert result["message"][1] == "speed: 'nan' is not a finite number"
    assert np.isnan(result["q"][1]).all() and np.isnan(result["energy"][1]) and np.isnan(result["steps"][1])
    good = [0, 2, 3]
    runs = serial_runs([cases[k] for k in good])
    for k, r in zip(good, runs):
        assert np.array_equal(result["q"][k], r.q) and result["steps"][k] == r.steps
    with pytest.raises(ValueError, match="speed: 'nan' is not a finite number"):
        appell.run(appell.load_scene(DISK), cases[1], **RUN)


def test_ctrl_c_stops_a_serial_sweep_between_two_cases():
    # A serial sweep is one batch on the main thread, the GIL released for
    # all of it; SIGINT is still seen between two cases. 1000 runs take
    # seconds (4.6 ms each in a Release build); the interrupt comes after
    # 0.3 s and must end the sweep at once.
    import signal
    import threading
    import time

    timer = threading.Timer(0.3, os.kill, (os.getpid(), signal.SIGINT))
    start = time.perf_counter()
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt):
            appell.sweep(DISK, {"speed": np.linspace(1.0, 3.0, 1000)}, duration=2.0)
    finally:
        timer.cancel()
    assert time.perf_counter() - start < 1.0


def test_a_process_pool_kept_for_many_sweeps_gives_the_serial_numbers():
    import concurrent.futures
    import multiprocessing

    cases = list(appell.grid_cases(GRID))
    with concurrent.futures.ProcessPoolExecutor(2, mp_context=multiprocessing.get_context("spawn")) as pool:
        first = appell.sweep(DISK, cases=cases[:3], executor=pool, **RUN)
        second = appell.sweep(DISK, cases=cases[3:], executor=pool, **RUN)
    assert first.executor == "ProcessPoolExecutor of 2"
    runs = serial_runs(cases)
    assert_equal_to_serial(first, runs[:3])
    assert_equal_to_serial(second, runs[3:])


def test_a_dask_local_cluster_of_two_workers_on_loopback_gives_the_serial_numbers():
    distributed = pytest.importorskip("distributed")  # python3-distributed (scripts/install-deps.sh)
    cases = list(appell.grid_cases(GRID))
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1",
                                  dashboard_address=None) as cluster, distributed.Client(cluster) as client:
        assert all(addr.startswith("tcp://127.0.0.1:") for addr in client.scheduler_info()["workers"])
        # Batches of one, of two, and as _batch_count cuts them after the pilot case.
        results = [appell.sweep(DISK, cases=cases, executor=client, batch_size=size, **RUN)
                   for size in (1, 2, None)]
        assert "dask tcp://127.0.0.1:" in results[0].executor
    runs = serial_runs(cases)
    for result in results:
        assert_equal_to_serial(result, runs)


def test_executor_dask_makes_its_own_loopback_cluster():
    pytest.importorskip("distributed")
    cases = list(appell.grid_cases({"speed": [1.0, 2.0]}))
    result = appell.sweep(DISK, cases=cases, executor="dask", workers=2, **RUN)
    assert result.executor == "dask LocalCluster of 2 workers"
    assert_equal_to_serial(result, serial_runs(cases))


@pytest.mark.parametrize("batch_size", [1, 4, None])
def test_linearize_sweep_equals_linearize_of_each_overridden_scene(batch_size):
    spins = np.linspace(1.0, 6.0, 6)
    result = appell.sweep(CHAIN, {"spin.velocity": spins}, analysis="linearize", executor="threads",
                          workers=2, batch_size=batch_size, cyclic=CYCLIC)
    base = appell.load_scene(CHAIN)
    for k, spin in enumerate(spins):
        scene, lines = appell.apply_overrides(base, [("spin.velocity", spin)])
        lin = appell.linearize(scene, cyclic=CYCLIC)
        eig = np.asarray(lin.eigenvalues)
        assert np.array_equal(result["eigenvalues"][k, : eig.size], eig)
        assert result["max_real"][k] == eig.real.max()
        assert result["dimension"][k] == lin.dimension
    # The upright disk is stable above a critical spin and unstable below it
    # (docs/equilibria.md: sqrt(g / (3 r)) for the thin disk of radius 0.3).
    critical = np.sqrt(9.81 / (3 * 0.3))
    assert all((result["max_real"] > 1e-6) == (spins < critical))


def test_random_draws_are_reproducible_from_their_seed_and_inside_their_laws():
    laws = {"speed": (1.0, 3.0), "root_joint.wx": ("normal", 0.5, 0.1)}
    a = appell.random_cases(laws, 50, seed=7)
    b = appell.random_cases(laws, 50, seed=7)
    c = appell.random_cases(laws, 50, seed=8)
    assert a == b and a != c
    speeds = np.array([dict(case)["speed"] for case in a])
    assert speeds.min() >= 1.0 and speeds.max() < 3.0
    lean = np.array([dict(case)["root_joint.wx"] for case in a])
    assert abs(lean.mean() - 0.5) < 4 * 0.1 / np.sqrt(50)
    result = appell.sweep(DISK, laws, samples=4, seed=7, executor="threads", workers=2, **RUN)
    assert np.array_equal(result["speed"], speeds[:4])  # one stream, drawn name by name
    assert result.cases == appell.random_cases(laws, 4, seed=7)
    assert_equal_to_serial(result, serial_runs(result.cases))


def test_a_misspelt_parameter_is_an_error_before_anything_runs():
    with pytest.raises(ValueError, match="wobble: not gravity, speed"):
        appell.sweep(DISK, {"wobble": [1.0, 2.0]}, executor="threads", **RUN)
    with pytest.raises(ValueError, match="give its path"):
        appell.sweep(appell.load_scene(DISK), {"speed": [1.0]}, executor="processes", **RUN)
    with pytest.raises(ValueError, match="batch_size must be a whole number ≥ 1, not 0"):
        appell.sweep(DISK, {"speed": [1.0]}, executor="threads", batch_size=0, **RUN)


def test_the_table_writes_to_csv_at_full_precision(tmp_path):
    result = appell.sweep(DISK, {"speed": [1.0, 2.0]}, **RUN)
    scene = appell.load_scene(DISK)
    path = tmp_path / "sweep.csv"
    result.to_csv(path, (scene.position_names, scene.velocity_names))
    lines = path.read_text().splitlines()
    header = lines[0].split(",")
    assert header[:2] == ["speed", "status"] and "q:root_joint.x" in header and "v:root_joint.vx" in header
    row = lines[2].split(",")
    assert float(row[header.index("q:root_joint.x")]) == result["q"][1, 0]
    assert float(row[header.index("friction_work")]) == result["friction_work"][1]


@pytest.mark.skipif(not os.environ.get("APPELL_CLI"), reason="APPELL_CLI (set by ctest) names the CLI")
@pytest.mark.parametrize("command", [["sweep", "--vary"], ["run", "--sweep"]])
def test_a_cli_sweep_row_is_the_same_run_as_the_python_sweeps(command):
    # `appell sweep` (and `appell run --sweep`, its one-name form) applies the
    # same override rules (run/src/overrides.cpp) to the same runner: its CSV
    # (the shortest text of each double) reads back the Python sweep's numbers.
    out = subprocess.run([os.environ["APPELL_CLI"], command[0], str(DISK), command[1], "speed=1:2:3",
                          "--format", "csv", "--duration", "0.3", "--integrator", "rk4", "--dt", "2e-3"],
                         capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    lines = out.stdout.splitlines()
    header = lines[0].split(",")
    result = appell.sweep(DISK, {"speed": [1.0, 1.5, 2.0]}, **RUN)
    scene = appell.load_scene(DISK)
    for k, line in enumerate(lines[1:]):
        row = line.split(",")
        assert row[header.index("status")] == "ok"
        q = [float(row[header.index("q:" + n)]) for n in scene.position_names]
        v = [float(row[header.index("v:" + n)]) for n in scene.velocity_names]
        assert np.array_equal(q, result["q"][k]) and np.array_equal(v, result["v"][k]), k
        for name in RUN_COLUMNS + ["relative_energy_deviation"]:
            assert float(row[header.index(name)]) == result[name][k], name
        assert int(row[header.index("steps")]) == result["steps"][k]
