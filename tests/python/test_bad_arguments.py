"""Numbers that are not numbers, and steps that lie (issue 41): every bad
argument is a ValueError naming it where it is passed — never a silent
fallback to a default, a NaN inside a step or a loop that never ends — and a
step that wrecks the energy is undone and reported, as the run library does."""

import math
import signal

import numpy as np
import pytest

import appell
from conftest import example

DISK = example("rolling_disk/rolling_disk.urdf")


@pytest.fixture(autouse=True)
def no_hang():
    """A hang (the NaN tolerance once looped for ever) fails the test in 60 s."""
    def timeout(*_):
        raise TimeoutError("the call did not return within 60 s")
    previous = signal.signal(signal.SIGALRM, timeout)
    signal.alarm(60)
    yield
    signal.alarm(0)
    signal.signal(signal.SIGALRM, previous)


def test_a_nan_or_negative_tolerance_is_refused_by_name():
    # Reproducer 6: scene.settings.tol = nan made advance_to(0.2) loop for ever.
    scene = appell.load_scene(DISK)
    with pytest.raises(ValueError, match=r"settings.tol must be finite and > 0 \(got nan\)"):
        scene.settings.tol = math.nan
    with pytest.raises(ValueError, match=r"settings.tol must be finite and > 0 \(got -1\)"):
        scene.settings.tol = -1.0
    with pytest.raises(ValueError, match=r"settings.dt must be finite and > 0 \(got inf\)"):
        scene.settings.dt = math.inf
    assert scene.settings.tol > 0  # unchanged
    with pytest.raises(ValueError, match=r"rtol must be finite and > 0 \(got inf\)"):
        appell.Simulation(scene, rtol=math.inf)
    with pytest.raises(ValueError, match=r"atol must be finite and > 0 \(got nan\)"):
        appell.Simulation(scene, atol=math.nan)
    with pytest.raises(ValueError, match=r"dt must be finite and > 0 \(got -0.01\)"):
        appell.Simulation(scene, dt=-0.01)
    with pytest.raises(ValueError, match=r"h_min must not exceed h_max \(got h_min = 1, h_max = 0.1\)"):
        appell.Simulation(scene, h_min=1.0, h_max=0.1)
    with pytest.raises(ValueError, match=r"h_max must be finite and > 0 \(got nan\)"):
        appell.Simulation(scene, h_max=math.nan)


def test_steps_must_be_positive_and_finite():
    # Reproducer 15: step(nan), step(-0.01) and advance_to(h=-1) silently took dt.
    sim = appell.Simulation(appell.load_scene(DISK), integrator="rk4", dt=1e-3)
    for bad, shown in ((math.nan, "nan"), (-0.01, "-0.01"), (0.0, "0")):
        with pytest.raises(ValueError, match=rf"step: h must be finite and > 0 \(got {shown}\)"):
            sim.step(bad)
    with pytest.raises(ValueError, match=r"advance_to: h must be finite and > 0 \(got -1\)"):
        sim.advance_to(0.1, h=-1.0)
    with pytest.raises(ValueError, match=r"advance_to: t_end must be finite"):
        sim.advance_to(math.nan)
    assert sim.t == 0.0  # nothing moved
    sim.step()  # no h: the simulation's dt
    assert sim.t == pytest.approx(1e-3, abs=1e-15)


def test_joint_forces_and_states_must_be_finite_and_quaternions_nonzero():
    scene = appell.load_scene(DISK)
    # Reproducer 15: scene.tau = [nan]*6 silently applied no force.
    with pytest.raises(ValueError, match=r"tau\[0\] is nan: every entry must be finite"):
        scene.tau = [math.nan] * 6
    with pytest.raises(ValueError, match=r"v0\[3\] is inf: every entry must be finite"):
        scene.v0 = [0, 0, 0, math.inf, 0, 0]
    sim = appell.Simulation(scene)
    with pytest.raises(ValueError, match=r"joint forces\[2\] is nan"):
        sim.set_joint_forces([0, 0, math.nan, 0, 0, 0])
    q = np.array(sim.q)
    q[3:7] = 0.0
    with pytest.raises(ValueError, match=r"the quaternion of joint 'root_joint' is zero"):
        sim.set_state(q=q)


def test_a_step_that_wrecks_the_energy_is_undone_and_reported():
    # Reproducer 13: one RK4 step of 1000 s on the disk returned ok with E
    # going from 4.6 J to 1.1e80 J.
    sim = appell.Simulation(appell.load_scene(DISK), integrator="rk4", dt=1e-3)
    q0, v0 = np.array(sim.q), np.array(sim.v)
    e0 = sim.energy
    status = sim.step(1000.0, check=False)
    assert not status.ok
    assert "the integration is diverging" in status.message
    assert "of the energy that moved" in status.message
    assert sim.t == 0.0 and np.array_equal(sim.q, q0) and np.array_equal(sim.v, v0)
    assert sim.energy == e0
    with pytest.raises(appell.SimulationError, match="diverging"):
        sim.step(1000.0)
    # Small steps are within the bound and keep going.
    assert sim.advance_to(0.05).ok and sim.t == pytest.approx(0.05)
    # Switched off, the same step is taken (and the energy is what it is).
    off = appell.Simulation(appell.load_scene(DISK), integrator="rk4", max_energy_error=math.inf)
    assert off.step(1000.0, check=False).ok and off.t == 1000.0
    assert off.energy > 1e6 * e0
    with pytest.raises(ValueError, match="max_energy_error must be > 0"):
        appell.Simulation(appell.load_scene(DISK), max_energy_error=math.nan)


def test_junk_nodes_are_refused_not_a_dead_interpreter():
    # Reproducer 1: `<1 " >` + 70 000 nested elements killed the interpreter
    # (stack overflow in the XML parser).
    xml = '<robot name="r">\n<1 " >' + "<x>" * 70000 + '<2 " >' + "</x>" * 70000 + "</robot>"
    with pytest.raises(appell.SceneError, match=r"junk.urdf:2: malformed XML: '<1 \" >' is not an element"):
        appell.load_scene_from_string(xml, name="junk.urdf")


def test_errors_say_what_was_wrong():
    # Reproducer 15: "Unable to cast Python instance" for a wrong type, a
    # SceneError with an empty message for a path that is not UTF-8.
    sim = appell.Simulation(appell.load_scene(DISK))
    with pytest.raises(TypeError, match=r"joint forces: expected None, an array of nv = 6 numbers or a callable"):
        sim.set_joint_forces("strong")
    # The callback is called at once (the reports of the current state include it).
    with pytest.raises(TypeError, match=r"the callback returned str, not an array of nv = 6 numbers"):
        sim.set_joint_forces(lambda t, q, v: "strong")
    with pytest.raises(appell.SceneError) as missing:
        appell.load_scene(b"/nonexistent/\xff\xfe.urdf")
    assert "nonexistent" in str(missing.value) and "\\xff" in str(missing.value)


def test_a_link_name_that_is_not_utf8_reads_back():
    # Reproducer 15: body_names raised UnicodeDecodeError for such a name.
    xml = ('<robot name="r"><link name="caf\x80"><inertial><mass value="1"/>'
           '<inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link></robot>')
    scene = appell.load_scene_from_string(xml.encode("latin-1"), name="latin1.urdf")
    assert scene.body_names == ["caf\\x80"]
