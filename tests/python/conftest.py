"""Shared helpers of the Python tests (run by ctest: tests/python/CMakeLists.txt).

The tests import the package built into the build tree (PYTHONPATH set by
ctest) and mirror the physics the C++ tests assert on the same scenes.
"""

import os
import pathlib

import numpy as np
import pytest

import appell

SOURCE_DIR = pathlib.Path(os.environ.get("APPELL_SOURCE_DIR", pathlib.Path(__file__).resolve().parents[2]))
EXAMPLES = SOURCE_DIR / "examples"
DATA = pathlib.Path(__file__).resolve().parent / "data"


def example(rel):
    """Path of an example scene, e.g. example("rolling_disk/rolling_disk.urdf")."""
    return EXAMPLES / rel


def tight_simulation(scene, formulation="tree", rtol=1e-10):
    """Dormand–Prince at a tight tolerance, as the C++ example tests simulate
    (tests/test_example_passive.cpp: rtol 1e-10, atol rtol/100, h_max 0.05)."""
    return appell.Simulation(scene, integrator="dopri5", formulation=formulation,
                             rtol=rtol, atol=rtol * 1e-2, h_max=0.05, dt=0.01)


def root_rotation(q):
    """Rotation matrix of the floating root joint's quaternion q[3:7] = (x, y, z, w)."""
    x, y, z, w = q[3:7] / np.linalg.norm(q[3:7])
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
    ])


def each_step(sim, t_end, h=0.01):
    """Steps to t_end one step at a time (the adaptive suggestion after the
    first), yielding after every accepted step, as the C++ tests' advance()."""
    while sim.t < t_end - 1e-14:
        status = sim.step(min(h, t_end - sim.t))
        h = status.h_next
        yield sim


@pytest.fixture
def cli():
    """The appell command-line program of this build (skips when unknown)."""
    path = os.environ.get("APPELL_CLI")
    if not path or not os.path.exists(path):
        pytest.skip("APPELL_CLI not set: the appell program is not known")
    return path
