"""The Python surface itself: names, state in and out, errors carrying the
C++ messages, events, joint forces, threads."""

import math
import threading

import numpy as np
import pytest

import appell
from conftest import example, tight_simulation

DISK = example("rolling_disk/rolling_disk.urdf")
BALL = example("bouncing_ball/bouncing_ball.urdf")


def test_names_and_sizes():
    scene = appell.load_scene(DISK)
    assert (scene.nq, scene.nv, scene.nbodies, scene.nrows) == (7, 6, 1, 3)
    assert scene.body_names == ["disk"]
    assert scene.joint_names == ["root_joint"] and scene.joint_types == ["floating"]
    assert scene.position_names[0] == "root_joint.x" and scene.position_names[-1] == "root_joint.qw"
    assert scene.velocity_names == ["root_joint." + c for c in ("wx", "wy", "wz", "vx", "vy", "vz")]
    assert scene.constraint_names == scene.contact_names == ["rim"]
    assert scene.row_labels == ["rim.tangent1", "rim.tangent2", "rim.normal"]
    assert scene.row_kinds == ["tangent1", "tangent2", "normal"]
    assert scene.constraint_rows("rim") == [0, 1, 2] and scene.row_index(0, "normal") == 2
    assert scene.settings.integrator == "dopri5" and scene.settings.duration == 5
    assert [e["name"] for e in appell.integrators()] == ["euler", "leapfrog", "rk4", "dopri5", "dop853"]
    assert "tree" in [f["name"] for f in appell.formulations()]
    assert scene.q0.shape == (7,) and scene.q0.dtype == np.float64


def test_state_round_trip():
    scene = appell.load_scene(DISK)
    sim = appell.Simulation(scene, integrator="rk4", dt=1e-3)
    assert (sim.integrator, sim.formulation, sim.dt) == ("rk4", "tree", 1e-3)
    assert np.array_equal(sim.q, scene.q0) and np.array_equal(sim.v, scene.v0) and sim.t == 0
    sim.advance_to(0.1)
    q, v = sim.q, sim.v
    sim.set_state(t=5.0)
    assert sim.t == 5.0 and np.array_equal(sim.q, q) and np.array_equal(sim.v, v)
    q[0] += 1.0                       # a copy: the simulation is not changed
    assert sim.q[0] != q[0]
    sim.set_state(q=scene.q0, v=scene.v0, t=0.0)
    assert np.array_equal(sim.q, scene.q0)
    assert sim.counters["steps"] == 100


def test_leapfrog_is_time_reversible_from_python():
    # The fixed-step leapfrog (docs/engine.md): 100 steps of 10 ms on the
    # rolling disk, the velocities reversed, 100 more come back to the start.
    scene = appell.load_scene(DISK)
    sim = appell.Simulation(scene, integrator="rattle", dt=1e-2)
    assert sim.integrator == "leapfrog"      # an alias, stored by its name
    sim.advance_to(1.0)
    sim.set_state(q=sim.q, v=-sim.v, t=0.0)
    sim.advance_to(1.0)
    assert np.max(np.abs(sim.q - scene.q0)) < 1e-12
    assert np.max(np.abs(sim.v + scene.v0)) < 1e-12


def test_errors_keep_the_cpp_message(tmp_path):
    with pytest.raises(appell.SceneError, match="cannot open file"):
        appell.load_scene(tmp_path / "missing.urdf")
    bad = (tmp_path / "bad.urdf")
    bad.write_text("<robot name='x'><link name='a'/><appell><contact name='c' link='nope' "
                   "kind='rolling'/></appell></robot>")
    with pytest.raises(appell.SceneError, match="bad.urdf"):
        appell.load_scene(bad)
    scene = appell.load_scene(DISK)
    with pytest.raises(ValueError, match="unknown integrator 'adams_bashforth'"):
        appell.Simulation(scene, integrator="adams_bashforth")
    with pytest.raises(ValueError, match="unknown formulation"):
        appell.Simulation(scene, formulation="lagrange")
    with pytest.raises(ValueError, match="contacts.settle_time must be finite and >= 0"):
        appell.Simulation(scene, settle_time=-1.0)
    sim = appell.Simulation(scene)
    with pytest.raises(ValueError, match="q must have size nq = 7"):
        sim.set_state(q=np.zeros(3))
    with pytest.raises(ValueError, match="non-finite"):
        sim.set_state(v=np.full(6, np.nan))
    with pytest.raises(ValueError, match="advance_to: t_end must be finite"):
        sim.advance_to(math.inf)
    with pytest.raises(KeyError):
        sim.constraint_lambdas("nope")
    with pytest.raises(IndexError):
        sim.body_pose(3)
    with pytest.raises(ValueError, match="size 7"):
        scene.q0 = np.zeros(2)
    with pytest.raises(ValueError):       # linearize: bad cyclic index (std::invalid_argument)
        appell.linearize(scene, cyclic=[42])


def test_failed_step_raises_or_reports():
    scene = appell.load_scene(DISK)
    sim = appell.Simulation(scene, integrator="rk4", dt=0.01)
    sim.set_joint_forces(lambda t, q, v: np.full(6, np.inf))
    with pytest.raises(appell.SimulationError):
        sim.step()
    status = sim.step(check=False)
    assert not status and status.message
    assert sim.t == 0.0                   # the last good state is kept


def test_joint_forces_constant_and_callable():
    scene = appell.load_scene(DISK)
    push = np.array([0, 0, 0.2, 0, 0, 0])          # a torque about the axle
    a = appell.Simulation(scene, integrator="rk4", dt=1e-3)
    b = appell.Simulation(scene, integrator="rk4", dt=1e-3)
    a.set_joint_forces(push)
    calls = []
    b.set_joint_forces(lambda t, q, v: calls.append(t) or push)
    a.advance_to(0.2)
    b.advance_to(0.2)
    assert calls and np.array_equal(a.q, b.q)
    free = appell.Simulation(scene, integrator="rk4", dt=1e-3)
    free.advance_to(0.2)
    assert np.max(np.abs(free.q - a.q)) > 1e-4
    # A Python error inside the callback is raised by the step, unchanged.
    # set_joint_forces evaluates the current state with the new forces, so
    # the error shows there, and again at the next step.
    with pytest.raises(ZeroDivisionError):
        b.set_joint_forces(lambda t, q, v: 1 / 0)
    t = b.t
    with pytest.raises(ZeroDivisionError):
        b.step()
    assert b.t == t
    b.set_joint_forces(None)
    b.step()


def test_bounce_events():
    scene = appell.load_scene(BALL)
    sim = tight_simulation(scene)
    assert sim.closed == [False]                    # in flight
    traj = sim.record(1.2)
    kinds = [e.kind for e in traj.events]
    assert kinds and kinds[0] == "bounce"
    first = traj.events[0]
    assert first.name == "floor_contact" and first.constraint == 0
    # Dropped from a height of 1 m: it lands at √(2 h / g), at √(2 g h).
    assert first.t == pytest.approx(math.sqrt(2 / 9.81), abs=1e-8)
    assert first.speed_before == pytest.approx(-math.sqrt(2 * 9.81), rel=1e-8)
    assert first.speed_after == pytest.approx(0.6 * math.sqrt(2 * 9.81), rel=1e-8)
    assert first.normal_impulse > 0
    assert sim.impact_energy_loss > 0
    # E + impact losses is conserved (a passive scene).
    assert sim.energy + sim.impact_energy_loss == pytest.approx(traj.energy[0], rel=1e-8)
    assert sim.counters["events"] == len(traj.events)


def run_disk(scene, t_end):
    sim = appell.Simulation(scene, integrator="rk4", dt=1e-3)
    sim.advance_to(t_end)
    return sim.q


def test_threads_give_the_serial_results():
    scene = appell.load_scene(DISK)
    serial = run_disk(scene, 0.5)
    results = [None] * 4

    def work(i):
        results[i] = run_disk(scene, 0.5)

    threads = [threading.Thread(target=work, args=(i,)) for i in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    for r in results:
        assert np.array_equal(r, serial)


def test_one_simulation_on_two_threads_is_refused():
    scene = appell.load_scene(DISK)
    sim = appell.Simulation(scene, integrator="rk4", dt=1e-4)
    started = threading.Event()
    errors = []

    def slow():
        started.set()
        sim.advance_to(2.0)

    worker = threading.Thread(target=slow)
    worker.start()
    started.wait()
    # While the worker steps (the GIL released), reading the state is refused.
    for _ in range(2000):
        try:
            sim.q
        except RuntimeError as e:
            errors.append(str(e))
            break
    worker.join()
    assert errors and "in use by another thread" in errors[0]
    assert sim.t == 2.0


def test_linearize_takes_cyclic_coordinates_by_name_or_index():
    # The upright disk rolling straight along x (consistent: no slip at the rim).
    scene = appell.load_scene(DISK)
    v = np.array([0.0, 0.0, -5.0, 1.5, 0.0, 0.0])
    sim = appell.Simulation(scene)
    sim.set_state(v=v)
    assert np.max(np.abs(sim.row_residuals()[0])) < 1e-15
    names = ["root_joint.wy", "root_joint.wz", "root_joint.vx", "root_joint.vy"]
    by_name = appell.linearize(scene, scene.q0, v, cyclic=names)
    by_index = appell.linearize(scene, scene.q0, v, cyclic=[1, 2, 3, 4])
    assert by_name.retained == by_index.retained == [0, 5]
    assert np.array_equal(by_name.matrix, by_index.matrix)
    assert by_name.constraint_residual < 1e-12
    # θ̇ at the reference: ω and the world velocity of the origin (here v itself).
    assert np.allclose(by_name.drift, v, atol=1e-15)
    with pytest.raises(KeyError, match="root_joint.spin"):
        appell.linearize(scene, cyclic=["root_joint.spin"])


def test_missing_visual_mesh_is_a_warning(tmp_path):
    urdf = tmp_path / "visual.urdf"
    urdf.write_text(
        "<robot name='r'><link name='b'><inertial><mass value='2'/><inertia ixx='1' ixy='0' "
        "ixz='0' iyy='1' iyz='0' izz='1'/></inertial><visual><geometry><mesh filename='nope.stl'/>"
        "</geometry></visual></link></robot>")
    scene = appell.load_scene(urdf)
    assert len(scene.warnings) == 1
    assert "visual.urdf:1: <mesh>" in scene.warnings[0]
    assert "nope.stl" in scene.warnings[0] and "visual only" in scene.warnings[0]
    assert appell.load_scene(DISK).warnings == []


def test_inertia_repairs_as_keywords(tmp_path):
    # The CAD export of TIAGo's arm_left_1_link on a floating base: moments
    # 0.00155679 0.00597627 0.00777394 break the triangle inequality by 3.1 %.
    urdf = tmp_path / "arm.urdf"
    urdf.write_text(
        "<robot name='r'><link name='arm_left_1_link'><inertial><mass value='1.563428'/>"
        "<inertia ixx='0.002471' ixy='0.001809' ixz='-0.001202' iyy='0.006132' iyz='-0.000494' "
        "izz='0.006704'/></inertial></link></robot>")
    plain = appell.load_scene(urdf)
    assert len(plain.warnings) == 1
    assert "violate the triangle inequality by 3.09" in plain.warnings[0]
    balanced = appell.load_scene(urdf, balance_inertia=True)
    assert len(balanced.warnings) == 1
    assert "repaired: smallest principal moment 0.00155679 raised to 0.00179767" in balanced.warnings[0]
    bounded = appell.load_scene_from_string(urdf.read_text(), name="arm.urdf", bound_mass=2.0)
    assert "mass 1.56343 kg raised to 2 (bound mass)" in bounded.warnings[0]
    assert bounded.total_mass == 2.0 and plain.total_mass == 1.563428
    with pytest.raises(appell.SceneError, match="must be finite and"):
        appell.load_scene(urdf, bound_inertia=-1.0)


def test_mimic_coupling_reaction(tmp_path):
    # A gear pair: the follower (inertia 0.08) turns at −0.4 × the leader
    # (0.02) under 0.3 N·m on the leader; the coupling's torque on the
    # follower is I_f · (−0.4) · α with α = τ / (I_l + 0.16 I_f).
    urdf = tmp_path / "gears.urdf"
    inertia = "<inertia ixx='{0}' ixy='0' ixz='0' iyy='{0}' iyz='0' izz='{1}'/>"
    urdf.write_text(
        "<robot name='gears'><link name='world'/>"
        "<link name='a'><inertial><mass value='1'/>" + inertia.format(0.02, 0.02) + "</inertial></link>"
        "<link name='b'><inertial><mass value='1'/>" + inertia.format(0.05, 0.08) + "</inertial></link>"
        "<joint name='ja' type='continuous'><parent link='world'/><child link='a'/><axis xyz='0 0 1'/></joint>"
        "<joint name='jb' type='continuous'><parent link='world'/><child link='b'/><origin xyz='1 0 0'/>"
        "<axis xyz='0 0 1'/><mimic joint='ja' multiplier='-0.4'/></joint>"
        "<appell><effort joint='ja' value='0.3'/></appell></robot>")
    scene = appell.load_scene(urdf)
    assert scene.mimic_names == scene.constraint_names == ["jb_mimic"]
    assert scene.row_labels == ["jb_mimic.coupling"]
    sim = appell.Simulation(scene, integrator="dopri5", rtol=1e-12, atol=1e-12)
    sim.advance_to(1.0)
    alpha = 0.3 / (0.02 + 0.16 * 0.08)
    assert sim.lambdas[0] == pytest.approx(0.08 * -0.4 * alpha, rel=1e-10)
    assert sim.q[1] == pytest.approx(-0.4 * sim.q[0], abs=1e-12)
    assert sim.q[0] == pytest.approx(0.5 * alpha, rel=1e-10)


def test_actuators_drive_the_scene():
    # examples/diff_drive/diff_drive_servo.urdf: velocity servos hold 5 rad/s
    # on both wheels until t = 3 s — straight at 0.5 m/s, as in C++.
    scene = appell.load_scene(example("diff_drive/diff_drive_servo.urdf"))
    assert scene.actuator_names == ["left_motor", "right_motor"]
    sim = appell.Simulation(scene)
    sim.advance_to(3.0)
    v = dict(zip(scene.velocity_names, sim.v))
    assert v["left_wheel_joint"] == pytest.approx(5.0, abs=1e-8)
    assert v["root_joint.vx"] == pytest.approx(0.5, abs=1e-9)
    assert abs(v["root_joint.wz"]) < 1e-12


def test_a_time_stepped_steps_contact_problem_carries_the_weight_within_its_cones():
    # The skid-steer standing on its four tyres (its command starts later):
    # the step's problem is four Coulomb cones on a symmetric positive
    # semidefinite W, its impulses inside the cones, their normal parts
    # carrying the weight over the 1 ms step; an event step records none.
    scene = appell.load_scene(example("skid_steer_step/skid_steer_step.urdf"))
    sim = appell.Simulation(scene, contacts="timestepping")
    h = 1e-3
    for _ in range(20):
        sim.step(h)
    p = sim.contact_problem()
    W, P, blocks = p["W"], p["P"], p["blocks"]
    assert p["t"] == pytest.approx(19 * h) and p["converged"]
    assert np.abs(W - W.T).max() <= 1e-12 * np.abs(W).max()
    assert np.linalg.eigvalsh(W).min() >= -1e-10 * np.abs(W).max()
    assert len(blocks) == 4 and all(b["friction_rows"] == 2 and b["equality_rows"] == 0 for b in blocks)
    assert all(b["name"] == scene.constraint_names[b["constraint"]] for b in blocks)
    for b in blocks:
        n = b["first"]
        assert np.linalg.norm(P[n + 1:n + 3]) <= b["mu"] * P[n] * (1 + 1e-9)
    load = sum(P[b["first"]] for b in blocks)
    assert load == pytest.approx(scene.total_mass * 9.81 * h, rel=1e-3)
    # Finish modes the step skipped (an earlier step's failed finish): none,
    # or one mode (0 open, 1 pushing, 2 sliding) per block.
    skipped = p["skipped_finish_modes"]
    assert len(skipped) in (0, len(blocks)) and all(m in (0, 1, 2) for m in skipped)
    events = appell.Simulation(scene, contacts="events")
    events.step(h)
    assert events.contact_problem() is None
