#!/usr/bin/env python3
"""The work balance of a run from Python: the bouncing ball (restitution 0.6,
backspin, μ 0.8) run for its scene's 4 s, its impacts as arrays with the
states around them, and

    E(t) + impact losses + friction work − joint work − support work = E(0)

checked with the numbers `appell.run` returns.

    pip install .                  # or PYTHONPATH=build/python
    python3 examples/python/energy_balance.py
"""

import pathlib

import numpy as np

import appell

scene = appell.load_scene(pathlib.Path(__file__).resolve().parents[1] / "bouncing_ball/bouncing_ball.urdf")
r = appell.run(scene)
print(r)
ev = r.events
print(f"{len(ev['t'])} events:", {k: n for k, n in r.event_counts.items() if n})
print(f"{'t (s)':>10} {'kind':>10} {'γ before':>10} {'γ after':>10} {'impulse':>10} {'height after':>13}")
for k in range(len(ev["t"])):
    print(f"{ev['t'][k]:10.5f} {ev['kind'][k]:>10} {ev['speed_before'][k]:10.5f} {ev['speed_after'][k]:10.5f} "
          f"{ev['normal_impulse'][k]:10.5f} {ev['q_after'][k, 2]:13.9f}")

balance = r.energy + r.impact_energy_loss + r.friction_work - r.joint_work - r.support_work
print(f"E0 = {r.energy0!r} J, E = {r.energy!r} J")
print(f"impacts took {r.impact_energy_loss!r} J, friction {r.friction_work!r} J, "
      f"joint forces put in {r.joint_work!r} J, supports {r.support_work!r} J")
print(f"balance − E0 = {balance - r.energy0:.3e} J ({(balance - r.energy0) / r.energy0:.1e} relative)")
assert abs(balance - r.energy0) <= 1e-6 * r.energy0
# Each impact happens touching the floor: the ball's centre one radius up.
impacts = np.array(ev["normal_impulse"]) > 0
assert np.allclose(ev["q_after"][impacts, 2], 0.1, atol=1e-8)
