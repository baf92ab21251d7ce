"""The rolling disk (examples/rolling_disk): the physics of
tests/test_example_passive.cpp (ExampleRollingDisk) through the bindings, and
agreement with the appell command line on the same run."""

import csv
import subprocess

import numpy as np
import pytest

import appell
from conftest import each_step, example, root_rotation, tight_simulation

DISK = example("rolling_disk/rolling_disk.urdf")


def test_energy_conserved_and_normal_load_balances_weight():
    scene = appell.load_scene(DISK)
    sim = tight_simulation(scene)
    m, g = scene.masses[0], 9.81
    n = scene.row_index("rim", "normal")
    E0 = sim.energy
    max_dev = max_res = max_gap = max_newton = 0.0
    loads = []
    for s in each_step(sim, 2.0):
        max_dev = max(max_dev, abs(s.energy - E0))
        max_res = max(max_res, s.velocity_residual)
        max_gap = max(max_gap, s.gap_residual)
        # The centre is the centre of mass; on flat ground the tangent rows are
        # horizontal, so the normal load alone balances m (g + a_z), with
        # a = R (v̇_lin + ω × v_lin) the world acceleration of the centre.
        q, v, vdot = s.q, s.v, s.vdot
        a = root_rotation(q) @ (vdot[3:6] + np.cross(v[0:3], v[3:6]))
        fn = s.lambdas[n]
        max_newton = max(max_newton, abs(fn - m * (g + a[2])))
        loads.append(fn)
    assert max_dev / abs(E0) < 1e-8
    assert max_res < 1e-10
    assert max_gap < 1e-10
    assert max_newton < 1e-8 * m * g
    assert min(loads) > 0.97 * m * g
    assert max(loads) < 1.03 * m * g
    # It did fall into a turn: the axle's lean changed.
    axle0, axle = root_rotation(scene.q0)[:, 2], root_rotation(sim.q)[:, 2]
    assert abs(axle[2] - axle0[2]) > 0.05


def test_reports_agree_with_the_engine():
    scene = appell.load_scene(DISK)
    sim = tight_simulation(scene)
    sim.advance_to(0.7)
    assert sim.t == pytest.approx(0.7, abs=1e-12)
    # Row residuals A v + b recomputed row by row: their max is the simulator's ‖A v + b‖∞.
    residual, gaps = sim.row_residuals()
    assert residual.shape == (scene.nrows,)
    assert np.max(np.abs(residual)) == pytest.approx(sim.velocity_residual, abs=1e-15)
    assert np.max(np.abs(gaps)) == pytest.approx(sim.gap_residual, abs=1e-15)
    # Energies: the simulator's and the model's at the same state.
    T, V = scene.energy(sim.q, sim.v)
    assert sim.kinetic_energy == pytest.approx(T, rel=1e-14)
    assert sim.potential_energy == pytest.approx(V, rel=1e-14, abs=1e-14)
    # The contact point lies on the ground under the centre, at the rim.
    p = sim.contact_points[0]
    assert abs(p[2]) < 1e-10
    assert np.allclose(sim.contact_normals[0], [0, 0, 1])
    assert np.linalg.norm(p - sim.q[0:3]) == pytest.approx(0.3, abs=1e-10)
    assert np.allclose(sim.body_pose("disk")[0:3, 3], sim.q[0:3])
    assert np.array_equal(sim.constraint_lambdas("rim"), sim.lambdas)
    # Recorded trajectories: start and end included, energy flat.
    traj = sim.record(1.0, every=5)
    assert traj.t[0] == pytest.approx(0.7) and traj.t[-1] == pytest.approx(1.0)
    assert traj.q.shape == (len(traj), scene.nq)
    assert traj.lambdas.shape == (len(traj), scene.nrows)
    assert np.ptp(traj.energy) < 1e-8 * abs(traj.energy[0])
    assert np.all(traj.velocity_residual < 1e-10)


def test_same_trajectory_as_the_command_line(cli, tmp_path):
    # RK4 with fixed steps is deterministic: the bindings and `appell run`
    # (runScene) must reach the same state.
    out = tmp_path / "disk.csv"
    subprocess.run([cli, "run", str(DISK), "--integrator", "rk4", "--dt", "0.005",
                    "--duration", "0.5", "--out", str(out), "--quiet"], check=True,
                   stdout=subprocess.DEVNULL)
    with open(out) as f:
        rows = list(csv.DictReader(f))
    scene = appell.load_scene(DISK)
    sim = appell.Simulation(scene, integrator="rk4", dt=0.005)
    sim.advance_to(0.5)
    last = rows[-1]
    q_cli = np.array([float(last["q:" + n]) for n in scene.position_names])
    v_cli = np.array([float(last["v:" + n]) for n in scene.velocity_names])
    lam_cli = np.array([float(last["lambda:" + n]) for n in scene.row_labels])
    assert float(last["time"]) == pytest.approx(sim.t, abs=1e-12)
    assert np.max(np.abs(q_cli - sim.q)) < 1e-12
    assert np.max(np.abs(v_cli - sim.v)) < 1e-11
    assert np.max(np.abs(lam_cli - sim.lambdas)) < 1e-9
    assert float(last["energy"]) == pytest.approx(sim.energy, rel=1e-13)
