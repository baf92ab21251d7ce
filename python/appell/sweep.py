"""Parameter sweeps: many cases of one scene through ``run`` or ``linearize``.

A case is a list of overrides (the names of ``appell run --set``,
docs/python.md): a grid of values, seeded random draws, or cases given one by
one. ``sweep`` runs every case — serially, on threads (the engine releases
the GIL), on processes, or on a Dask ``distributed`` cluster — and returns a
``SweepResult``: one row per case, as NumPy arrays. Each case is the same
computation as ``appell.run(scene, overrides)`` (or ``appell.linearize`` of
the overridden scene) called alone, so its numbers equal those bit for bit
whatever the executor.

Cases travel in batches: a batch is every k-th case of the list (_strides),
run by one call into the extension (``_appell.run_batch`` /
``linearize_batch``) with the GIL released for the whole batch, its table
coming back as NumPy columns — no Python runs per case, so threads never
wait for each other and a process or Dask worker pays one round trip per
batch. How many batches: ``_batch_count`` (the rule is written there and in
docs/python.md). Remote workers (processes, Dask) load the scene from its
file once per process, so the scene is given as a path there.
"""

from __future__ import annotations

import itertools
import numbers
import os
import time

import numpy as np

from . import _appell

__all__ = ["sweep", "grid_cases", "random_cases", "SweepResult"]


def grid_cases(parameters):
    """Every combination of the values of ``parameters`` (name → sequence of
    values; the last name varies fastest), as lists of (name, value)."""
    names = list(parameters)
    for values in itertools.product(*(list(parameters[n]) for n in names)):
        yield list(zip(names, values))


def random_cases(parameters, samples, seed):
    """``samples`` cases of independent draws, reproducible from ``seed``
    (NumPy's default generator, one stream drawn name by name). A name maps
    to ``(low, high)`` — uniform —, ``("normal", mean, sd)``, or a callable
    ``f(rng, samples)`` returning the values."""
    if samples is None or samples < 1:
        raise ValueError("samples must be a whole number ≥ 1")
    rng = np.random.default_rng(seed)
    columns = {}
    for name, law in parameters.items():
        if callable(law):
            values = list(law(rng, samples))
        elif len(law) == 3 and law[0] == "normal":
            values = rng.normal(law[1], law[2], samples).tolist()
        elif len(law) == 2:
            values = rng.uniform(law[0], law[1], samples).tolist()
        else:
            raise ValueError(f"{name}: give (low, high), ('normal', mean, sd) or a callable f(rng, n)")
        if len(values) != samples:
            raise ValueError(f"{name}: {len(values)} values drawn for {samples} samples")
        columns[name] = values
    return [[(n, columns[n][k]) for n in parameters] for k in range(samples)]


# Scenes loaded by this process, by (path, its size and modification time,
# load options): each worker process loads a scene once for all the batches
# it runs, and again only when its file changes.
_scenes = {}


def _scene_of(source, load_options):
    if isinstance(source, _appell.Scene):
        return source
    path = os.fspath(source)
    stat = os.stat(path)
    key = (path, stat.st_size, stat.st_mtime_ns, tuple(sorted(load_options.items())))
    if key not in _scenes:
        _scenes[key] = _appell.load_scene(source, **load_options)
    return _scenes[key]


def _run_batch(source, load_options, analysis, options, cases, check_signals=False):
    """One batch of cases, run in C++ with the GIL released: its columns, one
    entry per case in order (status and message as lists of str).
    ``check_signals``: Ctrl-C between two cases raises KeyboardInterrupt (a
    batch on the main thread)."""
    scene = _scene_of(source, load_options)
    batch = _appell.run_batch if analysis == "run" else _appell.linearize_batch
    return batch(scene, cases, check_signals=check_signals, **options)


def _merge(tables, order=None):
    """The batches' columns joined, row j being case order[j] (default: in
    turn), and put in case order: a 2-D column padded with NaN to its widest
    batch (the spectra of linearizations of different dimension); counts
    become floats with NaN where a case ended in an error."""
    columns = {}
    for key in tables[0]:
        parts = [t[key] for t in tables]
        if key in ("status", "message"):
            columns[key] = np.array([x for p in parts for x in p], dtype=object)
        elif parts[0].ndim == 2:
            width = max(p.shape[1] for p in parts)
            if any(p.shape[1] < width for p in parts):
                parts = [np.pad(p, ((0, 0), (0, width - p.shape[1])), constant_values=np.nan) for p in parts]
            columns[key] = np.concatenate(parts)
        else:
            columns[key] = np.concatenate(parts)
    if order is not None:
        rows = np.argsort(np.asarray(order), kind="stable")  # rows[k]: the row of case k
        columns = {key: col[rows] for key, col in columns.items()}
    errors = columns["status"] == "error"
    if errors.any():
        for key, col in columns.items():
            if col.dtype.kind == "i":
                col = col.astype(float)
                col[errors] = np.nan
                columns[key] = col
    return columns


class SweepResult:
    """One row per case: ``parameters`` (the override names) and the result
    columns, each a NumPy array indexed by case (``result["q"]`` is n × nq).

    Columns of a run: status, message, time, q, v, energy0, energy,
    impact_energy_loss, friction_work, joint_work, support_work,
    max_energy_deviation, relative_energy_deviation, max_velocity_residual,
    max_gap_residual, steps, events and events_<kind> (counts),
    wall_seconds. Of a linearization: status, message, q, v, dimension,
    eigenvalues (n × the largest dimension, NaN-padded), max_real, the three
    residuals, wall_seconds."""

    def __init__(self, parameters, cases, columns, executor, wall_seconds):
        self.parameters = list(parameters)
        self.cases = cases
        self.executor = executor
        self.wall_seconds = wall_seconds
        self.columns = {}
        for name in self.parameters:  # NaN where a case given one by one leaves a name out
            values = [dict(c).get(name) for c in cases]
            width = max((len(v) if hasattr(v, "__len__") else 1 for v in values if v is not None), default=1)
            nan = np.nan if width == 1 else [np.nan] * width
            self.columns[name] = np.array([nan if v is None else v for v in values], dtype=float)
        self.columns.update(columns)

    def __len__(self):
        return len(self.cases)

    def __getitem__(self, name):
        return self.columns[name]

    def __contains__(self, name):
        return name in self.columns

    def keys(self):
        return self.columns.keys()

    @property
    def ok(self):
        """Cases that ran to their end (status "ok")."""
        return self.columns["status"] == "ok"

    def to_csv(self, path, state_names=None):
        """Writes the scalar columns, and q and v one column each, at full
        precision (repr of the doubles); ``state_names`` = (position names,
        velocity names) of the scene name the q: and v: columns."""
        import csv

        header, getters = [], []
        for name, col in self.columns.items():
            if col.ndim == 1:
                header.append(name)
                getters.append(lambda k, c=col: c[k])
            elif col.dtype != object and name in ("q", "v"):
                labels = (state_names[0 if name == "q" else 1] if state_names
                          else [str(i) for i in range(col.shape[1])])
                for i, label in enumerate(labels):
                    header.append(f"{name}:{label}")
                    getters.append(lambda k, c=col, i=i: c[k, i])
        with open(path, "w", newline="") as f:
            w = csv.writer(f)
            w.writerow(header)
            for k in range(len(self)):
                w.writerow([_text(g(k)) for g in getters])

    def __repr__(self):
        ok = int(np.count_nonzero(self.ok)) if "status" in self.columns else 0
        return (f"<SweepResult: {len(self)} cases ({ok} ok) of {', '.join(self.parameters) or 'none'}"
                f" on {self.executor}, {self.wall_seconds:.3g} s>")


def _text(x):
    return repr(float(x)) if isinstance(x, (float, np.floating)) else str(x)


def sweep(scene, parameters=None, *, samples=None, seed=None, cases=None, analysis="run",
          executor="serial", workers=None, batch_size=None, load_options=None, **options):
    """Runs every case of a sweep and returns a ``SweepResult``.

    scene       a path to the scene (any executor) or a loaded ``Scene``
                (serial and threads: processes and Dask load it from its
                file, with ``load_options`` as ``load_scene`` takes them)
    parameters  name → values: a grid of every combination; with
                ``samples``, name → law (``random_cases``) and ``seed``
    cases       instead: a list of cases, each a list of (name, value) or a dict
    analysis    "run" (``appell.run``'s keywords in ``options``: duration,
                dt, integrator, …) or "linearize" (``appell.linearize``'s:
                cyclic, formulation, …) at each case's initial state
    executor    "serial", "threads", "processes", "dask" (a LocalCluster of
                ``workers`` processes on 127.0.0.1, closed at the end), a
                ``distributed.Client`` (its cluster: local or a scheduler's
                address for many machines), or a ``concurrent.futures``
                pool — a Client or a pool kept for many sweeps starts its
                workers, and loads the scene in them, once
    workers     threads or processes (default: the cores; a Client's own
                worker threads)
    batch_size  cases per batch (default: ``_batch_count``'s rule — from
                the first case's wall time, batches of at least 5 ms on
                threads, 20 ms on processes and 100 ms on Dask, up to four
                per worker; docs/python.md)
    """
    if analysis not in ("run", "linearize"):
        raise ValueError(f"analysis must be 'run' or 'linearize', not {analysis!r}")
    if cases is None:
        if parameters is None:
            raise ValueError("give parameters (a grid or, with samples, random laws) or cases")
        cases = (random_cases(parameters, samples, seed) if samples is not None
                 else list(grid_cases(parameters)))
        names = list(parameters)
    else:
        cases = [list(c.items()) if isinstance(c, dict) else list(c) for c in cases]
        names = []
        for c in cases:
            names += [n for n, _ in c if n not in names]
    load_options = dict(load_options or {})
    import concurrent.futures as cf

    remote = not ((isinstance(executor, str) and executor in ("serial", "threads"))
                  or isinstance(executor, cf.ThreadPoolExecutor))
    if remote and isinstance(scene, _appell.Scene):
        raise ValueError("processes and Dask workers load the scene themselves: give its path "
                         "(and load_options), not a loaded Scene")
    if batch_size is not None and not (isinstance(batch_size, numbers.Integral) and batch_size >= 1):
        raise ValueError(f"batch_size must be a whole number ≥ 1, not {batch_size!r}")
    local = _scene_of(scene, load_options)  # the names' check; the pilot case of remote executors
    if not remote:
        scene = local
    _check_names(local, cases)
    start = time.perf_counter()
    columns, label = _execute(_SweepPlan(scene, local, load_options, analysis, options, cases), executor, workers,
                              batch_size)
    return SweepResult(names, cases, columns, label, time.perf_counter() - start)


def _check_names(scene, cases):
    """A misspelt name or a wrong count fails here, before anything runs:
    each distinct name applied once, with the first value it has."""
    first = {}
    for case in cases:
        for name, value in case:
            first.setdefault(name, value)
    for name, value in first.items():
        _appell.apply_overrides(scene, [(name, value)], check_initial_state=False)


# The least work a batch should carry, by executor, against its own cost per
# batch — measured with batches of one bicycle linearization on one worker
# (python/bench/results.md): 0.10 ms on a thread (the call, reading the
# cases, building the columns, the future), 0.5 ms on a spawned process
# (pickling the batch and its table, the pipe), 4 ms for a Dask task on a
# LocalCluster (the scheduler's bookkeeping and the messages between client,
# scheduler and worker; Dask's own guidance is ~1 ms per task and tasks of
# ~100 ms, "Dask Best Practices"). Each keeps that cost to 2–4 % of a batch.
MIN_BATCH_SECONDS = {"threads": 0.005, "processes": 0.02, "dask": 0.1}
BATCHES_PER_WORKER = 4


def _batch_count(cases, workers, case_seconds, min_batch_seconds):
    """How many batches: a multiple of the workers, so that cases of equal
    cost end together — up to BATCHES_PER_WORKER per worker, so that cases of
    unequal cost balance, but no more than leave each batch at least
    ``min_batch_seconds`` of work (``case_seconds`` a case's, from the pilot
    case), and at least one per worker; never more than the cases."""
    fill = cases * case_seconds / (min_batch_seconds * workers)
    per_worker = max(1, min(BATCHES_PER_WORKER, int(fill)))
    return max(1, min(cases, workers * per_worker))


def _strides(first, n, count):
    """``count`` batches of the cases first … n − 1, batch i taking every
    count-th case from first + i — not contiguous slices: along a grid the
    cost of a case often grows (a faster run takes more steps), and strided
    batches share that gradient alike, so that equal batches end together.
    Their sizes are within one of each other."""
    return [range(first + i, n, count) for i in range(count)]


class _SweepPlan:
    """What every batch shares: the scene (a path for remote workers), the
    one loaded here, its load options, the analysis and its options, the
    cases."""

    def __init__(self, scene, local, load_options, analysis, options, cases):
        self.scene, self.local, self.load_options = scene, local, load_options
        self.analysis, self.options, self.cases = analysis, options, cases

    def args(self):
        return (self.scene, self.load_options, self.analysis, self.options)

    def batches(self, workers, batch_size, kind):
        """The first case's table (the pilot, run here and timed, when the
        batch size is to be chosen; None else) and the case indices of each
        batch of the rest (_strides)."""
        n = len(self.cases)
        if batch_size is not None:
            return None, _strides(0, n, -(-n // batch_size))
        start = time.perf_counter()
        pilot = _run_batch(self.local, self.load_options, self.analysis, self.options, self.cases[:1], True)
        seconds = time.perf_counter() - start
        count = _batch_count(n - 1, workers, seconds, MIN_BATCH_SECONDS[kind]) if n > 1 else 0
        return pilot, _strides(1, n, count)

    def cases_of(self, indices):
        return [self.cases[k] for k in indices]


def _gathered(pilot, batches, tables):
    """The pilot's and the batches' tables as one, in case order."""
    order = ([0] if pilot is not None else []) + [k for b in batches for k in b]
    return _merge(([pilot] if pilot is not None else []) + list(tables), order)


def _execute(sweep, executor, workers, batch_size):
    if not sweep.cases:
        return {}, "nothing"
    if isinstance(executor, str) and executor == "serial":
        return _merge([_run_batch(*sweep.args(), sweep.cases, True)]), "serial"
    if isinstance(executor, str) and executor in ("threads", "processes"):
        import concurrent.futures as cf
        import multiprocessing

        workers = workers or os.cpu_count() or 1
        if executor == "threads":
            pool = cf.ThreadPoolExecutor(workers)
        else:  # spawn: no fork of a process whose threads may hold locks
            pool = cf.ProcessPoolExecutor(workers, mp_context=multiprocessing.get_context("spawn"))
        with pool:
            return _on_pool(pool, sweep, workers, batch_size, executor), f"{workers} {executor}"
    if isinstance(executor, str) and executor == "dask":
        from distributed import Client, LocalCluster

        workers = workers or os.cpu_count() or 1
        with LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                          host="127.0.0.1", dashboard_address=None) as cluster, Client(cluster) as client:
            columns = _on_client(client, sweep, workers, batch_size)
        return columns, f"dask LocalCluster of {workers} workers"
    if hasattr(executor, "submit") and hasattr(executor, "gather"):  # a distributed.Client
        threads = sum(executor.nthreads().values()) or 1
        return _on_client(executor, sweep, workers or threads, batch_size), f"dask {executor.scheduler.address}"
    if hasattr(executor, "submit"):  # a concurrent.futures pool the caller keeps for many sweeps
        import concurrent.futures as cf

        workers = workers or getattr(executor, "_max_workers", None) or os.cpu_count() or 1
        kind = "threads" if isinstance(executor, cf.ThreadPoolExecutor) else "processes"
        return _on_pool(executor, sweep, workers, batch_size, kind), f"{type(executor).__name__} of {workers}"
    raise ValueError(f"executor must be 'serial', 'threads', 'processes', 'dask' or a distributed.Client, "
                     f"not {executor!r}")


def _on_pool(pool, sweep, workers, batch_size, kind):
    pilot, batches = sweep.batches(workers, batch_size, kind)
    futures = [pool.submit(_run_batch, *sweep.args(), sweep.cases_of(b)) for b in batches]
    return _gathered(pilot, batches, [f.result() for f in futures])


class _Batch:
    """A Dask task's argument: opaque to Dask, which would otherwise walk
    the cases' lists and tuples looking for tasks and keys in them."""

    __slots__ = ("args", "cases")

    def __init__(self, args, cases):
        self.args, self.cases = args, cases


def _run_task(batch):
    return _run_batch(*batch.args, batch.cases)


def _on_client(client, sweep, workers, batch_size):
    """One Dask task per batch, submitted by one client.map (one message to
    the scheduler, where a submit per batch would wait out the client's 10 ms
    batching of messages after the first)."""
    pilot, batches = sweep.batches(workers, batch_size, "dask")
    tasks = [_Batch(sweep.args(), sweep.cases_of(b)) for b in batches]
    futures = client.map(_run_task, tasks, pure=False)
    return _gathered(pilot, batches, client.gather(futures))
