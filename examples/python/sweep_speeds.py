#!/usr/bin/env python3
"""A parameter sweep from Python: the rolling disk launched at eight forward
speeds (the scene's lean rate kept, its spin following the speed), each run
1 s on two threads, one row per run — then the same speeds through the
linearization of a steadily rolling disk (tests/data/linearize/disk_chain),
where the upright disk becomes stable above a critical spin.

    pip install .                  # or PYTHONPATH=build/python
    python3 examples/python/sweep_speeds.py
"""

import pathlib

import numpy as np

import appell

ROOT = pathlib.Path(__file__).resolve().parents[2]

runs = appell.sweep(ROOT / "examples/rolling_disk/rolling_disk.urdf", {"speed": np.linspace(1.0, 3.0, 8)},
                    executor="threads", workers=2, duration=1.0)
print(runs)
print(f"{'speed':>6} {'status':>7} {'x (m)':>8} {'y (m)':>8} {'|ΔE| (J)':>10} {'residual':>10}")
for k in range(len(runs)):
    print(f"{runs['speed'][k]:6.3f} {runs['status'][k]:>7} {runs['q'][k, 0]:8.4f} {runs['q'][k, 1]:8.4f} "
          f"{runs['max_energy_deviation'][k]:10.2e} {runs['max_velocity_residual'][k]:10.2e}")
assert runs.ok.all()

lin = appell.sweep(ROOT / "tests/data/linearize/disk_chain.urdf", {"spin.velocity": np.linspace(1.0, 6.0, 11)},
                   analysis="linearize", executor="threads", workers=2,
                   cyclic=["plane.x", "plane.y", "plane.theta", "spin"])
print(lin)
for spin, growth in zip(lin["spin.velocity"], lin["max_real"]):
    print(f"spin {spin:4.1f} rad/s: largest real part {growth:+.4f} 1/s ({'unstable' if growth > 1e-6 else 'stable'})")
