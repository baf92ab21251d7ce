"""Parameter sweeps: many cases of one scene through ``run`` or ``linearize``.

A case is a list of overrides (the names of ``appell run --set``,
docs/python.md): a grid of values, seeded random draws, or cases given one by
one. ``sweep`` runs every case — serially, on threads (the engine releases
the GIL), on processes, or on a Dask ``distributed`` cluster — and returns a
``SweepResult``: one row per case, as NumPy arrays. Each case is the same
computation as ``appell.run(scene, overrides)`` (or ``appell.linearize`` of
the overridden scene) called alone, so its numbers equal those bit for bit
whatever the executor.

Cases travel in batches (about four per worker), so the per-case cost of an
executor is one share of a batch's round trip, not a round trip each. Remote
workers (processes, Dask) load the scene from its file once per process, so
the scene is given as a path there.
"""

from __future__ import annotations

import itertools
import math
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


# Scenes loaded by this process, by (path, load options): each worker
# process loads a scene once for all the batches it runs.
_scenes = {}


def _scene_of(source, load_options):
    if isinstance(source, _appell.Scene):
        return source
    key = (os.fspath(source), tuple(sorted(load_options.items())))
    if key not in _scenes:
        _scenes[key] = _appell.load_scene(source, **load_options)
    return _scenes[key]


def _run_case(scene, overrides, analysis, options):
    start = time.perf_counter()
    try:
        if analysis == "run":
            r = _appell.run(scene, overrides, **options)
            row = {
                "status": "ok" if r.ok else "failed",
                "message": r.failure,
                "time": r.time,
                "q": r.q,
                "v": r.v,
                "energy0": r.energy0,
                "energy": r.energy,
                "impact_energy_loss": r.impact_energy_loss,
                "friction_work": r.friction_work,
                "joint_work": r.joint_work,
                "support_work": r.support_work,
                "max_energy_deviation": r.max_energy_deviation,
                "relative_energy_deviation": r.relative_energy_deviation,
                "max_velocity_residual": r.max_velocity_residual,
                "max_gap_residual": r.max_gap_residual,
                "steps": r.steps,
                "events": sum(r.event_counts.values()),
            }
            for kind, count in r.event_counts.items():
                row["events_" + kind] = count
        else:
            case, _ = _appell.apply_overrides(scene, overrides)
            lin = _appell.linearize(case, **options)
            eig = np.asarray(lin.eigenvalues)
            row = {
                "status": "ok",
                "message": "",
                "q": case.q0,
                "v": case.v0,
                "dimension": lin.dimension,
                "eigenvalues": eig,
                "max_real": float(eig.real.max()) if eig.size else -math.inf,
                "steady_residual": lin.steady_residual,
                "symmetry_residual": lin.symmetry_residual,
                "constraint_residual": lin.constraint_residual,
            }
    except (ValueError, RuntimeError, KeyError, IndexError) as e:
        row = {"status": "error", "message": str(e)}
    row["wall_seconds"] = time.perf_counter() - start
    return row


def _run_batch(source, load_options, analysis, options, batch):
    """One batch of (index, overrides): its rows, in order."""
    scene = _scene_of(source, load_options)
    return [(k, _run_case(scene, overrides, analysis, options)) for k, overrides in batch]


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

    def __init__(self, parameters, cases, rows, executor, wall_seconds):
        self.parameters = list(parameters)
        self.cases = cases
        self.executor = executor
        self.wall_seconds = wall_seconds
        self.columns = {}
        for name in self.parameters:  # NaN where a case given one by one leaves a name out
            values = [dict(c).get(name) for c in cases]
            width = max((np.size(v) for v in values if v is not None), default=1)
            nan = np.nan if width == 1 else [np.nan] * width
            self.columns[name] = np.array([nan if v is None else v for v in values], dtype=float)
        keys = []
        for row in rows:
            keys += [k for k in row if k not in keys]
        for key in keys:
            values = [row.get(key) for row in rows]
            self.columns[key] = _column(values)

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


def _column(values):
    present = [v for v in values if v is not None]
    if not present:
        return np.array(values, dtype=object)
    first = present[0]
    if isinstance(first, str):
        return np.array(["" if v is None else v for v in values], dtype=object)
    if isinstance(first, np.ndarray):
        width = max(v.shape[0] for v in present)
        dtype = np.complex128 if any(np.iscomplexobj(v) for v in present) else np.float64
        out = np.full((len(values), width), np.nan, dtype=dtype)
        for k, v in enumerate(values):
            if v is not None:
                out[k, : v.shape[0]] = v
        return out
    if all(isinstance(v, (int, np.integer)) and not isinstance(v, bool) for v in present):
        if len(present) == len(values):
            return np.array(values, dtype=np.int64)
    return np.array([np.nan if v is None else v for v in values], dtype=float)


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
    batch_size  cases per task (default: about four tasks per worker)
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
    if not remote and not isinstance(scene, _appell.Scene):
        scene = _appell.load_scene(scene, **load_options)
    _check_names(scene if not remote else _scene_of(scene, load_options), cases)
    start = time.perf_counter()
    rows, label = _execute(scene, load_options, analysis, options, cases, executor, workers, batch_size)
    return SweepResult(names, cases, rows, label, time.perf_counter() - start)


def _check_names(scene, cases):
    """A misspelt name or a wrong count fails here, before anything runs:
    each distinct name applied once, with the first value it has."""
    first = {}
    for case in cases:
        for name, value in case:
            first.setdefault(name, value)
    for name, value in first.items():
        _appell.apply_overrides(scene, [(name, value)], check_initial_state=False)


def _batches(cases, workers, batch_size):
    n = len(cases)
    size = batch_size or max(1, math.ceil(n / (4 * max(1, workers))))
    indexed = list(enumerate(cases))
    return [indexed[i:i + size] for i in range(0, n, size)]


def _collect(n, results):
    rows = [None] * n
    for batch in results:
        for k, row in batch:
            rows[k] = row
    return rows


def _execute(scene, load_options, analysis, options, cases, executor, workers, batch_size):
    n = len(cases)
    args = (scene, load_options, analysis, options)
    if isinstance(executor, str) and executor == "serial":
        return _collect(n, [_run_batch(*args, list(enumerate(cases)))]), "serial"
    if isinstance(executor, str) and executor in ("threads", "processes"):
        import concurrent.futures as cf
        import multiprocessing

        workers = workers or os.cpu_count() or 1
        batches = _batches(cases, workers, batch_size)
        if executor == "threads":
            pool = cf.ThreadPoolExecutor(workers)
        else:  # spawn: no fork of a process whose threads may hold locks
            pool = cf.ProcessPoolExecutor(workers, mp_context=multiprocessing.get_context("spawn"))
        with pool:
            futures = [pool.submit(_run_batch, *args, b) for b in batches]
            return _collect(n, [f.result() for f in futures]), f"{workers} {executor}"
    if isinstance(executor, str) and executor == "dask":
        from distributed import Client, LocalCluster

        workers = workers or os.cpu_count() or 1
        with LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                          host="127.0.0.1", dashboard_address=None) as cluster, Client(cluster) as client:
            rows = _on_client(client, args, cases, workers, batch_size)
        return rows, f"dask LocalCluster of {workers} workers"
    if hasattr(executor, "submit") and hasattr(executor, "gather"):  # a distributed.Client
        threads = sum(executor.nthreads().values()) or 1
        return _on_client(executor, args, cases, workers or threads, batch_size), f"dask {executor.scheduler.address}"
    if hasattr(executor, "submit"):  # a concurrent.futures pool the caller keeps for many sweeps
        workers = workers or getattr(executor, "_max_workers", None) or os.cpu_count() or 1
        futures = [executor.submit(_run_batch, *args, b) for b in _batches(cases, workers, batch_size)]
        return _collect(n, [f.result() for f in futures]), f"{type(executor).__name__} of {workers}"
    raise ValueError(f"executor must be 'serial', 'threads', 'processes', 'dask' or a distributed.Client, "
                     f"not {executor!r}")


def _on_client(client, args, cases, workers, batch_size):
    batches = _batches(cases, workers, batch_size)
    futures = [client.submit(_run_batch, *args, b, pure=False) for b in batches]
    return _collect(len(cases), client.gather(futures))
