#!/usr/bin/env python3
"""The rolling disk from Python: load the example scene, simulate 3 s, and
print the lean, the normal load, the energy error and the constraint
residuals as the disk falls into a turn.

    cmake --build build            # builds build/python/appell
    PYTHONPATH=build/python /usr/bin/python3 examples/python/rolling_disk.py
"""

import pathlib

import numpy as np

import appell

scene = appell.load_scene(pathlib.Path(__file__).resolve().parents[1] / "rolling_disk/rolling_disk.urdf")
print(scene)
print("coordinates:", scene.position_names)
print("contact rows:", scene.row_labels)

sim = appell.Simulation(scene)          # the scene's settings: dopri5, tol 1e-10, tree solver
normal = scene.row_index("rim", "normal")
E0 = sim.energy

print(f"{'t':>5} {'lean (deg)':>11} {'normal load (N)':>16} {'|E - E0| / E0':>14} {'|Av + b|':>9}")
for t in np.arange(0.5, 3.01, 0.5):
    sim.advance_to(t)
    axle = sim.body_pose("disk")[0:3, 2]           # the disk's axle, world frame
    lean = np.degrees(np.arcsin(abs(axle[2])))      # 0: upright
    print(f"{sim.t:5.1f} {lean:11.3f} {sim.lambdas[normal]:16.6f} "
          f"{abs(sim.energy - E0) / abs(E0):14.2e} {sim.velocity_residual:9.1e}")

print("contact point:", sim.contact_points[0], "normal:", sim.contact_normals[0])

# A recorded run: every step's state as arrays.
traj = sim.record(4.0)
print(f"recorded {len(traj)} samples; the centre's height stays in "
      f"[{traj.q[:, 2].min():.4f}, {traj.q[:, 2].max():.4f}] m")
