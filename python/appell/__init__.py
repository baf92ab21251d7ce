"""appell: multibody dynamics with exact nonholonomic rolling contacts.

A thin package around the compiled extension ``appell._appell`` (pybind11).
Load a scene from a URDF with an ``<appell>`` block, simulate it, read the
state, reactions, contact frames and energies as NumPy arrays, and analyse
equilibria and linearizations. docs/python.md documents the API.

    import appell
    scene = appell.load_scene("examples/rolling_disk/rolling_disk.urdf")
    sim = appell.Simulation(scene)
    sim.advance_to(1.0)
    print(sim.q, sim.energy, sim.constraint_lambdas("rim"))

``Simulation.step``, ``advance_to`` and ``record`` release the GIL, so
independent simulations run in parallel on threads (one thread per
Simulation; using one Simulation from two threads at once raises).
``run(scene, overrides)`` runs a scene as ``appell run --set`` does, with its
work terms and events as arrays; ``sweep`` runs many such cases on threads,
processes or a Dask cluster (python/appell/sweep.py).
"""

from ._appell import (
    ContactEvent,
    EquilibriumResult,
    LinearizationResult,
    ModelError,
    MultiStartResult,
    RunResult,
    Scene,
    SceneError,
    Simulation,
    SimulationError,
    SimulationSettings,
    StepStatus,
    Trajectory,
    apply_overrides,
    contact_event_kinds,
    contact_schemes,
    find_equilibria,
    find_equilibrium,
    formulations,
    integrators,
    linearize,
    load_scene,
    load_scene_from_string,
    run,
)
from .sweep import SweepResult, grid_cases, random_cases, sweep

__version__ = "0.1.0"

__all__ = [
    "ContactEvent",
    "EquilibriumResult",
    "LinearizationResult",
    "ModelError",
    "MultiStartResult",
    "RunResult",
    "Scene",
    "SceneError",
    "Simulation",
    "SimulationError",
    "SimulationSettings",
    "StepStatus",
    "Trajectory",
    "SweepResult",
    "apply_overrides",
    "contact_event_kinds",
    "contact_schemes",
    "find_equilibria",
    "find_equilibrium",
    "formulations",
    "integrators",
    "linearize",
    "load_scene",
    "load_scene_from_string",
    "grid_cases",
    "random_cases",
    "run",
    "sweep",
]
