"""appell.run: the work terms close the energy balance
    E(t) + impact losses + friction work − joint work − support work = E(0)
from Python, the events come as arrays with the states around them, and
overrides say what they changed (the rolling disk keeps its lean rate when
its speed is set). The command line prints the same work terms at full
precision and lists the overrides.
"""

import os
import subprocess

import numpy as np
import pytest

import appell
from conftest import example, SOURCE_DIR

BALL = example("bouncing_ball/bouncing_ball.urdf")
DISK = example("rolling_disk/rolling_disk.urdf")
CHAIN = SOURCE_DIR / "tests/data/linearize/disk_chain.urdf"


def balance(r):
    return r.energy + r.impact_energy_loss + r.friction_work - r.joint_work - r.support_work


def test_the_bouncing_balls_impacts_and_friction_close_its_energy_balance():
    r = appell.run(appell.load_scene(BALL))
    assert r.ok and r.time == pytest.approx(4.0)
    # Restitution 0.6 with μ 0.8: each impact's friction impulse stops the
    # backspinning ball's slip at once (no sliding phase, no slip event), so
    # the impacts take all the energy lost and sliding friction none.
    assert r.impact_energy_loss > 0.5 * r.energy0
    assert r.friction_work == 0 and r.event_counts["slip"] == 0
    assert r.joint_work == 0 and r.support_work == 0
    assert balance(r) == pytest.approx(r.energy0, rel=1e-7)
    ev = r.events
    n = len(ev["t"])
    assert n == sum(r.event_counts.values()) > 0
    assert r.event_counts["bounce"] >= 10 and r.event_counts["touchdown"] == 1  # the last one: at rest
    for key, shape in (("q_before", (n, 7)), ("v_before", (n, 6)), ("q_after", (n, 7)), ("v_after", (n, 6))):
        assert ev[key].shape == shape, key
    assert np.all(ev["t_before"] <= ev["t"]) and np.all(np.diff(ev["t"]) >= 0)
    impacts = ev["normal_impulse"] > 0
    assert impacts.sum() >= 2
    # At each impact the ball touches the floor (centre one radius up), and it
    # was above the floor or touching it the state before.
    assert np.allclose(ev["q_after"][impacts, 2], 0.1, atol=1e-8)
    assert np.all(ev["q_before"][impacts, 2] >= 0.1 - 1e-8)
    # Newton's restitution on the normal speed at the bounces the ball leaves.
    bounces = impacts & (ev["speed_after"] > 1e-3)
    assert bounces.any()
    assert np.allclose(ev["speed_after"][bounces], -0.6 * ev["speed_before"][bounces], rtol=1e-9)


def test_the_sliding_blocks_friction_work_closes_its_balance():
    # The block slides down its incline (μ_s 0.5, μ_k 0.4): friction takes
    # energy at the rate μ_k N |v|, and no impact takes any.
    r = appell.run(appell.load_scene(example("block_incline/block_incline.urdf")))
    assert r.ok and r.event_counts["slip"] > 0
    assert r.friction_work > 0.5 * r.energy0 and r.impact_energy_loss == 0
    assert balance(r) == pytest.approx(r.energy0, rel=1e-10)


def test_a_constant_joint_torque_does_the_work_of_torque_times_angle():
    # disk_chain's spin joint driven by τ = 0.05 N·m: its work is τ Δθ exactly
    # (the integrator's own quadrature of τ·v, to its tolerance).
    scene = appell.load_scene(CHAIN)
    tau = 0.05
    r = appell.run(scene, [("spin.velocity", 5.0), ("spin.effort", tau)], duration=1.0,
                   integrator="dopri5", tol=1e-10)
    assert r.ok
    spin = scene.position_names.index("spin")
    start, _ = appell.apply_overrides(scene, [("spin.velocity", 5.0)])
    assert r.joint_work == pytest.approx(tau * (r.q[spin] - start.q0[spin]), rel=1e-8)
    assert r.joint_work > 0 and r.impact_energy_loss == 0
    assert balance(r) == pytest.approx(r.energy0, rel=1e-8)
    assert r.overrides[:2] == ["spin.velocity = 5 (spin velocity)", "spin.effort = 0.05 (spin effort (τ))"]


def test_setting_the_disks_speed_keeps_its_lean_rate_and_names_the_spin_it_changed():
    base = appell.load_scene(DISK)
    scene, lines = appell.apply_overrides(base, {"speed": 2.0})
    # v = (ω; v) in the disk's frame: lean rate ω_x = 0.5 and the lateral
    # 0.15 stay; rolling without slip on radius 0.3 needs spin −v/0.3.
    assert np.array_equal(scene.v0[[0, 1, 4, 5]], base.v0[[0, 1, 4, 5]])
    assert scene.v0[3] == 2.0
    assert scene.v0[2] == pytest.approx(-2.0 / 0.3, rel=1e-12)
    assert lines[0] == "speed = 2 (root_joint.vx)"
    assert lines[1].startswith("completed by the constraints: root_joint.wz -5 → -6.66666666666666")
    assert len(lines) == 2
    # The same speed as the scene's changes nothing and says so.
    same, lines = appell.apply_overrides(base, {"speed": 1.5})
    assert np.array_equal(same.v0, base.v0) and lines == ["speed = 1.5 (root_joint.vx)"]


def test_mu_and_gravity_overrides_change_the_run():
    scene = appell.load_scene(BALL)
    frictionless = appell.run(scene, {"floor_contact.mu": 0.0}, duration=1.0)
    assert frictionless.ok and frictionless.friction_work == 0
    # No friction: the backspin never changes (ω_y stays −20).
    assert frictionless.v[1] == pytest.approx(-20.0, abs=1e-9)
    moon = appell.run(scene, {"gravity": (0, 0, -1.62)}, duration=0.5)
    assert moon.ok and moon.event_counts["touchdown"] == 0  # still falling from 1.1 m
    assert moon.q[2] == pytest.approx(1.1 - 0.5 * 1.62 * 0.25, abs=1e-9)
    with pytest.raises(ValueError, match="floor_contact.mu: μ must be ≥ 0"):
        appell.run(scene, {"floor_contact.mu": -1.0})
    with pytest.raises(ValueError, match="gravity: needs gx,gy,gz, got 2 numbers"):
        appell.apply_overrides(scene, {"gravity": (0, -9.81)})


@pytest.mark.skipif(not os.environ.get("APPELL_CLI"), reason="APPELL_CLI (set by ctest) names the CLI")
def test_the_cli_summary_lists_the_overrides_and_prints_work_terms_in_full():
    cli = os.environ["APPELL_CLI"]
    out = subprocess.run([cli, "run", str(DISK), "--set", "speed=2", "--duration", "0.05", "--quiet"],
                         capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    assert "override     speed = 2 (root_joint.vx)\n" in out.stdout
    assert "override     completed by the constraints: root_joint.wz -5 → -6.66666666666666" in out.stdout
    out = subprocess.run([cli, "run", str(BALL), "--quiet"], capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    r = appell.run(appell.load_scene(BALL))
    # In full: the printed numbers read back as the run's doubles (the
    # shortest round-trip text, as Python's repr writes them too).
    assert f"impacts took {r.impact_energy_loss!r} J" in out.stdout
    line = next(l for l in out.stdout.splitlines() if l.startswith("work "))
    assert line == (f"work         joint forces 0 J, moving supports 0 J in; impacts {r.impact_energy_loss!r} J, "
                    f"friction 0 J out")
    # Slips, no impact: the impacts took exactly 0 J, friction all of it.
    block = example("block_incline/block_incline.urdf")
    out = subprocess.run([cli, "run", str(block), "--quiet"], capture_output=True, text=True)
    r = appell.run(appell.load_scene(block))
    assert f"contact events ({r.event_counts['slip']}; impacts took 0 J):" in out.stdout
    assert f"impacts 0 J, friction {r.friction_work!r} J out" in out.stdout
