"""The ball on a turntable (examples/ball_turntable): the centre runs round a
circle at (2/7) Ω whatever its initial velocity (Neimark & Fufaev, *Dynamics
of Nonholonomic Systems*, 1972; the homogeneous ball, I = (2/5) m r²).
Mirrors ExampleBallTurntable of tests/test_example_passive.cpp."""

import math

import numpy as np

import appell
from conftest import each_step, example, root_rotation, tight_simulation

BALL = example("ball_turntable/ball_turntable.urdf")
OMEGA = 2.0                     # the file's turntable rate
RATE = 2 * OMEGA / 7            # the centre's angular rate
PERIOD = 2 * math.pi / RATE     # 7π/Ω


def centre_velocity(sim):
    return root_rotation(sim.q) @ sim.v[3:6]


def spin_z(sim):
    return (root_rotation(sim.q) @ sim.v[0:3])[2]


def test_centre_circles_at_two_sevenths_of_the_table_rate():
    scene = appell.load_scene(BALL)
    assert scene.support_names == ["table"]
    sim = tight_simulation(scene)
    p0, v0 = scene.q0[0:3].copy(), centre_velocity(sim)
    speed0, spin0 = np.linalg.norm(v0[0:2]), spin_z(sim)
    assert speed0 > 0.1
    dev = {"speed": 0.0, "spin": 0.0, "height": 0.0, "residual": 0.0, "gap": 0.0}

    def run_to(t_end):
        for s in each_step(sim, t_end):
            dev["speed"] = max(dev["speed"], abs(np.linalg.norm(centre_velocity(s)[0:2]) - speed0))
            dev["spin"] = max(dev["spin"], abs(spin_z(s) - spin0))
            dev["height"] = max(dev["height"], abs(s.q[2] - 0.1))
            dev["residual"] = max(dev["residual"], s.velocity_residual)
            dev["gap"] = max(dev["gap"], s.gap_residual)

    # A quarter period: the velocity has turned by exactly π/2, counter-clockwise.
    run_to(PERIOD / 4)
    vq = centre_velocity(sim)
    assert abs(vq[0] + v0[1]) < 1e-7
    assert abs(vq[1] - v0[0]) < 1e-7
    # A full period 7π/Ω: back where it started, with the same velocity.
    run_to(PERIOD)
    assert np.linalg.norm(sim.q[0:3] - p0) < 1e-7
    assert np.linalg.norm(centre_velocity(sim) - v0) < 1e-7
    assert dev["speed"] < 1e-8
    assert dev["spin"] < 1e-8
    assert dev["height"] < 1e-10
    assert dev["residual"] < 1e-10
    assert dev["gap"] < 1e-10


def test_centre_follows_the_analytic_circle():
    # a_G = (2/7) Ω e_z × v_G: v_G(t) = Rot_z(kt) v_G(0), and the centre
    # x(t) = x(0) − (1/k) e_z × (v_G(t) − v_G(0)) (tests/test_scene_ball.cpp).
    scene = appell.load_scene(BALL)
    sim = tight_simulation(scene)
    x0, v0 = scene.q0[0:3].copy(), centre_velocity(sim)
    ez = np.array([0.0, 0.0, 1.0])
    for i in range(1, 9):
        t = 0.6 * i
        sim.advance_to(t)
        c, s = math.cos(RATE * t), math.sin(RATE * t)
        vt = np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]]) @ v0
        xt = x0 - np.cross(ez, vt - v0) / RATE
        assert np.linalg.norm(centre_velocity(sim) - vt) < 1e-8, t
        assert np.linalg.norm(sim.q[0:3] - xt) < 1e-8, t
        assert sim.velocity_residual < 1e-10


def test_rate_independent_of_initial_velocity():
    # A different (sliding) guess, projected onto the rolling constraints.
    scene = appell.load_scene(BALL)
    scene.v0 = np.array([-4.0, 6.0, -1.0, 0.2, -0.5, 0.0])
    report = scene.check_initial_state(project=True)
    assert report["projected"]
    sim = tight_simulation(scene)
    v0 = centre_velocity(sim)
    sim.advance_to(PERIOD / 2)
    assert np.linalg.norm(centre_velocity(sim)[0:2] + v0[0:2]) < 1e-7  # turned by π
    traj = sim.record(PERIOD)
    assert np.linalg.norm(sim.q[0:3] - scene.q0[0:3]) < 1e-7
    assert traj.velocity_residual.max() < 1e-10


def test_formulations_agree_at_the_start():
    scene = appell.load_scene(BALL)
    tree, kkt = tight_simulation(scene, "tree"), tight_simulation(scene, "kkt")
    assert np.max(np.abs(tree.vdot - kkt.vdot)) < 1e-9 * max(1.0, np.max(np.abs(kkt.vdot)))
    assert np.max(np.abs(tree.lambdas - kkt.lambdas)) < 1e-8 * max(1.0, np.max(np.abs(kkt.reaction)))
