"""The Whipple benchmark bicycle (examples/bicycle) through appell.sweep and
linearize: 200 forward speeds from 3 to 7 m/s, on every executor — serial,
two threads, two spawned processes and a two-worker Dask LocalCluster on
127.0.0.1 — equal to appell.linearize of each overridden scene bit for bit,
and the stability it finds that of Meijaard, Papadopoulos, Ruina & Schwab
(2007), "Linearized dynamics equations for the balance and steer of a
bicycle: a benchmark and review", §5: the weave mode grows below
4.2924 m/s, the capsize mode above 6.0243 m/s, nothing grows between.
"""

import numpy as np
import pytest

import appell
from conftest import example

BIKE = example("bicycle/bicycle.urdf")
CYCLIC = ["plane.x", "plane.y", "plane.theta", "rear_spin", "front_spin"]
SPEEDS = np.linspace(3.0, 7.0, 200)
WEAVE, CAPSIZE = 4.29238253634111, 6.02426201538837  # Meijaard et al. (2007), Table 2


@pytest.fixture(scope="module")
def serial():
    """The 200 speeds one by one: appell.linearize of each overridden scene."""
    base = appell.load_scene(BIKE)
    out = []
    for speed in SPEEDS:
        scene, _ = appell.apply_overrides(base, [("plane.vx", speed)])
        out.append(np.asarray(appell.linearize(scene, cyclic=CYCLIC).eigenvalues))
    return out


def assert_equal_to_serial(result, serial):
    assert list(result["status"]) == ["ok"] * len(SPEEDS)
    assert np.array_equal(result["plane.vx"], SPEEDS)
    for k, eig in enumerate(serial):
        assert np.array_equal(result["eigenvalues"][k, : eig.size], eig), k
        assert result["max_real"][k] == eig.real.max(), k


@pytest.mark.parametrize("executor", ["serial", "threads", "processes", "dask"])
def test_two_hundred_speeds_equal_the_serial_linearizations_bit_for_bit(executor, serial):
    if executor == "dask":
        pytest.importorskip("distributed")  # python3-distributed (scripts/install-deps.sh)
    result = appell.sweep(BIKE, {"plane.vx": SPEEDS}, analysis="linearize", executor=executor, workers=2,
                          cyclic=CYCLIC)
    assert len(result) == 200
    assert_equal_to_serial(result, serial)


def test_the_sweep_finds_the_weave_and_capsize_speeds(serial):
    # Running straight is steady at every speed, so the speed's own direction
    # is a zero eigenvalue (|μ| ~ the finite differences' 1e-7); growth is a
    # real part above 1e-4. The oscillating weave pair has an imaginary part,
    # the capsize mode none.
    far = np.abs(SPEEDS - WEAVE) > 0.02
    far &= np.abs(SPEEDS - CAPSIZE) > 0.02
    for speed, eig, keep in zip(SPEEDS, serial, far):
        if not keep:
            continue
        growing = eig[eig.real > 1e-4]
        weave = any(abs(z.imag) > 1.0 for z in growing)
        capsize = any(abs(z.imag) < 1e-9 for z in growing)
        assert weave == (speed < WEAVE), speed
        assert capsize == (speed > CAPSIZE), speed
