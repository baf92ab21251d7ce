"""The Chaplygin sleigh on an incline. Mirrors tests/test_sleigh_equilibria.cpp
(Emelyanova & Fufaev's example, after Neimark & Fufaev, *Dynamics of
Nonholonomic Systems*, 1972): with the centre of mass perpendicular to the
blade the sleigh has equilibria "of the second kind" at headings φ = 0, π,
held by the blade's lateral reaction λ = ±m g sin α; the usual sleigh
(centre of mass along the blade, examples/sleigh) has none, and slides
down the slope (ExampleSleigh of tests/test_example_passive.cpp)."""

import math

import numpy as np
import pytest

import appell
from conftest import DATA, each_step, example, root_rotation, tight_simulation

ALPHA = 0.35
E1 = np.array([1.0, 0.0, 0.0])                                   # across the slope
DOWN = np.array([0.0, math.cos(ALPHA), -math.sin(ALPHA)])        # down the slope
NORMAL = np.array([0.0, math.sin(ALPHA), math.cos(ALPHA)])


def heading(q):
    blade = root_rotation(q)[:, 0]
    return math.atan2(blade @ DOWN, blade @ E1)


def blade_lambda(result):
    """The blade's lateral force projected on the paper's row (sin φ, −cos φ)."""
    blade = root_rotation(result.q)[:, 0]
    lateral = np.cross(NORMAL, blade)
    lateral /= np.linalg.norm(lateral)
    phi = heading(result.q)
    row = math.sin(phi) * E1 - math.cos(phi) * DOWN
    return result.lambdas[0] * (lateral @ row)


def guesses(scene, headings, seed=7):
    """Configurations at these headings, at random points of the plane, a
    little tilted and lifted off it (the gaps are not closed)."""
    rng = np.random.default_rng(seed)
    out = []
    for phi in headings:
        x, y = rng.uniform(-1, 1, 2)
        # θ = (rotation in the body frame, displacement in the world): body z is
        # the incline's normal at q0, so θ_z turns the heading.
        theta = np.concatenate([[0.05 * rng.uniform(-1, 1), 0.05 * rng.uniform(-1, 1), phi],
                                x * E1 + y * DOWN + np.array([0.03, -0.02, 0.04])])
        out.append(scene.retract(scene.q0, theta))
    return out


def test_lateral_sleigh_equilibria_of_the_second_kind():
    scene = appell.load_scene(DATA / "lateral_sleigh.urdf")
    assert scene.constraint_names == ["blade", "foot1", "foot2"]
    assert scene.row_labels[0] == "blade.lateral"
    mg = scene.total_mass * 9.81
    found = set()
    for g in guesses(scene, [0.4, -0.3, 0.9, math.pi + 0.3, math.pi - 0.6, 2.4]):
        r = appell.find_equilibrium(scene, g)
        assert r.converged, r.message
        assert r.gap_residual < 1e-10
        phi = heading(r.q)
        assert abs(math.sin(phi)) < 1e-9, phi
        sign = 1 if math.cos(phi) > 0 else -1
        found.add(sign)
        assert blade_lambda(r) == pytest.approx(sign * mg * math.sin(ALPHA), abs=1e-9 * mg)
        # The three normal rows carry the weight's normal component.
        assert r.lambdas[1] + r.lambdas[2] + r.lambdas[3] == pytest.approx(mg * math.cos(ALPHA), abs=1e-9 * mg)
        assert r.manifold_dimension == 2        # x and y are free
        assert r.redundant_rows == 0
        assert r.row_labels[0] == "blade/lateral"
    assert found == {1, -1}


def test_find_equilibria_multistart():
    scene = appell.load_scene(DATA / "lateral_sleigh.urdf")
    ms = appell.find_equilibria(scene, guesses(scene, [0.5, -0.7, 2.6, 3.6], seed=3))
    assert len(ms.runs) == 4
    assert all(r.converged for r in ms.runs)
    assert len(ms.distinct) == 4                # different x, y: all distinct points


def test_usual_sleigh_has_no_equilibrium_and_the_finder_says_so():
    scene = appell.load_scene(example("sleigh/sleigh.urdf"))
    mg = scene.total_mass * 9.81
    for g in guesses(scene, [0.0, 0.5, 1.5, -1.2, math.pi, 2.0]):
        r = appell.find_equilibrium(scene, g)
        assert not r.converged, f"false equilibrium at {r.q}"
        assert not r
        assert "no equilibrium near the guess" in r.message
        # Gravity along the slope has nothing to balance it.
        assert r.force_residual > 1e-3 * mg


def test_lateral_sleigh_linearization_at_rest_across_the_slope():
    # At φ = 0 the state on the constraint manifold is (x, y, φ; u, ω): k = 5.
    # The linearized flow is nilpotent (tests/test_linearization.cpp: yaw is
    # neutral, δφ drives δu̇ = g sin α δφ, x and y are free): every eigenvalue
    # is zero and L⁵ = 0.
    scene = appell.load_scene(DATA / "lateral_sleigh.urdf")
    r = appell.find_equilibrium(scene)
    assert r.converged
    lin = appell.linearize(scene, r.q, np.zeros(scene.nv))
    assert lin.dimension == 5
    assert lin.steady_residual < 1e-9
    L = lin.matrix
    assert np.linalg.norm(np.linalg.matrix_power(L, 5)) < 1e-6 * np.linalg.norm(L) ** 5
    assert lin.count_zero_eigenvalues(1e-2) == 5


def test_usual_sleigh_turns_down_the_slope_energy_conserved():
    alpha = 0.3
    down = np.array([0.0, math.cos(alpha), -math.sin(alpha)])
    scene = appell.load_scene(example("sleigh/sleigh.urdf"))
    sim = tight_simulation(scene)
    E0 = sim.energy

    def misalignment():
        return math.acos(np.clip(root_rotation(sim.q)[:, 0] @ down, -1, 1))

    assert misalignment() == pytest.approx(math.pi / 2, abs=1e-12)   # starts across the slope
    max_dev = max_res = max_gap = 0.0
    at = {}
    for t_end in (3.0, 6.0):
        for s in each_step(sim, t_end):
            max_dev = max(max_dev, abs(s.energy - E0))
            max_res = max(max_res, s.velocity_residual)
            max_gap = max(max_gap, s.gap_residual)
        at[t_end] = misalignment()
    assert at[6.0] < 0.05
    assert at[6.0] < at[3.0]
    # Sliding down, centre of mass first: the blade point moves along +blade, downhill.
    vel = root_rotation(sim.q) @ sim.v[3:6]
    assert vel @ down > 10.0
    assert max_dev / abs(E0) < 1e-8
    assert max_res < 1e-10
    assert max_gap < 1e-10
