"""Contact fabric and stress (Herman 2013 eqs 10-11; the Physics page: physics-observables)
on lattices with known answers, their invariances, and the hard-disc
collision virial."""
from __future__ import annotations

import math

import numpy as np
import pytest

from physics import (HERMAN2013, Contacts, FloeField, HardDiskSimulation, HertzSimulation,
                     PeriodicBox, collision_stress, contacts_within, fabric, stress)
from physics import harddisk_kernels as HK
from physics.observables import near_pairs

R = 2.0                      # floe radius of the lattices [m]
SQUEEZE = 1e-3               # lattice spacing 2R(1 - SQUEEZE): overlap 0.2 % of R
# Overlaps are differences of positions 1e4 times larger, so their rounding
# error is ~1e-12 relative and a Hertz force (∝ δ^1.5) varies by ~2e-12 from
# contact to contact: stresses are compared to STRESS_RTOL, geometry to 1e-12.
STRESS_RTOL = 1e-9


def _hertz_lattice(positions, box):
    """A HertzSimulation at rest on the given lattice and its contacts."""
    n = len(positions)
    field = FloeField(np.asarray(positions, dtype=float), np.full(n, R), thickness=1.0)
    sim = HertzSimulation(field, box, HERMAN2013.contact, None, dt=1e-4)
    return sim, sim.contacts()


def square_lattice(n=6):
    a = 2 * R * (1 - SQUEEZE)
    g = (np.arange(n) + 0.5) * a
    x, y = np.meshgrid(g, g)
    return np.column_stack([x.ravel(), y.ravel()]), PeriodicBox(n * a), a


def hexagonal_lattice(nx=6, ny=6):
    a = 2 * R * (1 - SQUEEZE)
    h = a * math.sqrt(3) / 2
    pos = [((ix + 0.5 * (iy % 2) + 0.25) * a, (iy + 0.5) * h)
           for iy in range(ny) for ix in range(nx)]
    return np.array(pos), PeriodicBox(nx * a, ny * h), a


def rows_lattice(n=6, rows=4):
    """Rows of touching floes along x, rows 3R apart (no contact across)."""
    a = 2 * R * (1 - SQUEEZE)
    pos = [((ix + 0.5) * a, (iy + 0.5) * 3 * R) for iy in range(rows) for ix in range(n)]
    return np.array(pos), PeriodicBox(n * a, rows * 3 * R), a


# -- lattices: exact to rounding ---------------------------------------------

def _isotropic_lattice(positions, box, z):
    """Contacts of a lattice where every floe has z contacts: checks
    Z_c = z exactly (a ratio of contact counts), Z_a = 0 (to 1e-12), f_nr = 1
    and returns (sim, contacts)."""
    sim, c = _hertz_lattice(positions, box)
    n = len(positions)
    assert len(c) == z * n // 2
    fab = fabric(c, n)
    assert fab.z_c == z
    assert fab.z_a == pytest.approx(0.0, abs=1e-12)
    assert fab.f_nr == 1.0 and np.all(fab.coordination == z)
    return sim, c


def test_square_lattice_fabric_and_isotropic_stress():
    """Every floe touches its 4 neighbours: Z_c = 4, Z_a = 0, f_nr = 1;
    σ_xx = σ_yy = F/a (one x and one y contact of length a per floe per
    cell a²), σ_xy = 0, τ = 0 (fabric to 1e-12, stress to STRESS_RTOL)."""
    pos, box, a = square_lattice()
    sim, c = _isotropic_lattice(pos, box, 4)
    n = len(pos)
    f = c.normal_force
    assert f.min() > 0 and np.ptp(f) <= STRESS_RTOL * f.max()
    s = stress(c, box.area, n_floes=n)
    p = f.mean() / a
    assert s.tensor[0, 0] == pytest.approx(p, rel=STRESS_RTOL)
    assert s.tensor[1, 1] == pytest.approx(p, rel=STRESS_RTOL)
    assert abs(s.tensor[0, 1]) < STRESS_RTOL * p and abs(s.tensor[1, 0]) < STRESS_RTOL * p
    assert s.pressure == pytest.approx(p, rel=STRESS_RTOL)
    assert s.shear < STRESS_RTOL * p
    # the engine's own helpers give the same objects
    assert sim.fabric().z_c == pytest.approx(4.0, rel=1e-12)
    np.testing.assert_allclose(sim.contact_stress().tensor, s.tensor, rtol=1e-12)


def test_hexagonal_lattice_fabric():
    """Six contacts per floe at 60° spacing: Z_c = 6, Z_a = 0 and an
    isotropic stress σ_xx = σ_yy, σ_xy = 0 (fabric to 1e-12, stress to
    STRESS_RTOL)."""
    pos, box, _ = hexagonal_lattice()
    _, c = _isotropic_lattice(pos, box, 6)
    assert math.isnan(fabric(c, len(pos)).direction)
    s = stress(c, box.area)
    assert s.tensor[0, 0] == pytest.approx(s.tensor[1, 1], rel=STRESS_RTOL)
    assert abs(s.tensor[0, 1]) < STRESS_RTOL * s.pressure
    assert s.pressure > 0                       # compression positive


def test_rows_of_floes_are_uniaxial():
    """Rows along x: Z_c = 2, Z_a = 1, principal fabric axis along x;
    σ_yy = 0 and p = τ = σ_xx / 2 (to 1e-12 relative)."""
    pos, box, _ = rows_lattice()
    _, c = _hertz_lattice(pos, box)
    fab = fabric(c, len(pos))
    assert fab.z_c == pytest.approx(2.0, rel=1e-12)
    assert fab.z_a == pytest.approx(1.0, rel=1e-12)
    assert fab.direction == pytest.approx(0.0, abs=1e-12)
    s = stress(c, box.area)
    assert s.tensor[0, 0] > 0
    assert abs(s.tensor[1, 1]) < 1e-12 * s.tensor[0, 0]
    assert s.pressure == pytest.approx(s.shear, rel=1e-12)
    assert s.pressure == pytest.approx(0.5 * s.tensor[0, 0], rel=1e-12)
    assert s.direction == pytest.approx(0.0, abs=1e-12)


def test_rattlers_are_left_out_of_the_fabric():
    """A chain of three floes along y: only the middle floe has two
    contacts, so N_n = 1, f_nr = 1/3, R = 2 e_y ⊗ e_y (Z_c = 2, Z_a = 1,
    principal axis along y)."""
    pos = np.array([[0.0, 0.0], [0.0, 2.0], [0.0, 4.0]])
    c = contacts_within(pos, np.ones(3), PeriodicBox(50.0), gap=1e-9)
    fab = fabric(c, 3)
    assert list(fab.coordination) == [1, 2, 1]
    assert fab.f_nr == pytest.approx(1 / 3)
    np.testing.assert_allclose(fab.tensor, [[0, 0], [0, 2]], atol=1e-15)
    assert fab.direction == pytest.approx(math.pi / 2, rel=1e-12)
    # no non-rattlers at all: an empty, defined fabric
    empty = fabric(contacts_within(pos[:2], np.ones(2), PeriodicBox(50.0), 1e-9), 2)
    assert empty.z_c == 0.0 and empty.f_nr == 0.0 and empty.z_a == 0.0


# -- invariances ----------------------------------------------------------------

def _random_contacts(seed, n=60, k=200):
    rng = np.random.default_rng(seed)
    pos = rng.uniform(0, 100, (n, 2))
    radii = rng.uniform(0.5, 2.0, n)
    i = rng.integers(0, n, k)
    j = (i + rng.integers(1, n, k)) % n
    d = pos[j] - pos[i]
    dist = np.hypot(d[:, 0], d[:, 1])
    force = rng.normal(0, 1e3, (k, 2))
    return Contacts.from_geometry(pos, radii, i, j, d / dist[:, None], dist, force), n


def _rotated(c, theta):
    rot = np.array([[math.cos(theta), -math.sin(theta)], [math.sin(theta), math.cos(theta)]])
    turn = lambda v: v @ rot.T  # noqa: E731
    return Contacts(c.i, c.j, turn(c.normal), c.overlap, c.normal_force, c.tangential_force,
                    turn(c.force), turn(c.contact_point), turn(c.branch_i), turn(c.branch_j)), rot


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_stress_is_the_sum_of_per_floe_stresses(seed):
    """Σ_i σ_i = σ to 1e-12 relative, with arbitrary (non-central) forces."""
    c, n = _random_contacts(seed)
    s = stress(c, 1e4, n_floes=n)
    assert s.per_floe.shape == (n, 2, 2)
    np.testing.assert_allclose(s.per_floe.sum(axis=0), s.tensor, rtol=1e-12,
                               atol=1e-12 * np.abs(s.tensor).max())


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_contact_number_is_the_count_ratio(seed):
    """Z_c of a random contact table is exactly the number of contact ends on
    non-rattlers over the number of non-rattlers (counted here floe by floe),
    and equals tr R (to 1e-12: R sums ~100 products of unit-vector components)."""
    c, n = _random_contacts(seed, k=60)            # ~2 contacts per floe: some rattlers
    coordination = [0] * n
    for a, b in zip(c.i.tolist(), c.j.tolist()):
        coordination[a] += 1
        coordination[b] += 1
    ends = [k for k in coordination if k >= 2]
    assert 0 < len(ends) < n                       # rattlers and non-rattlers both present
    fab = fabric(c, n)
    assert fab.z_c == sum(ends) / len(ends)
    assert fab.z_c == pytest.approx(np.trace(fab.tensor), rel=1e-12)
    assert fab.z_c == pytest.approx(fab.eigenvalues.sum(), rel=1e-12)


@pytest.mark.parametrize("theta", [0.3, 1.1, 2.5])
def test_rotating_the_configuration_rotates_the_tensors(theta):
    """Rotating every vector by Q gives R' = Q R Qᵀ and σ' = Q σ Qᵀ; the
    invariants Z_c, Z_a, p, τ are unchanged and the principal axes turn by
    θ (all to 1e-12)."""
    c, n = _random_contacts(7)
    cr, q = _rotated(c, theta)
    f0, f1 = fabric(c, n), fabric(cr, n)
    np.testing.assert_allclose(f1.tensor, q @ f0.tensor @ q.T, atol=1e-12)
    assert f1.z_c == pytest.approx(f0.z_c, rel=1e-12)
    assert f1.z_a == pytest.approx(f0.z_a, rel=1e-10)
    assert (f1.direction - f0.direction - theta) % math.pi == pytest.approx(0.0, abs=1e-9) or \
        (f1.direction - f0.direction - theta) % math.pi == pytest.approx(math.pi, abs=1e-9)
    s0, s1 = stress(c, 1e4, n_floes=n), stress(cr, 1e4, n_floes=n)
    scale = np.abs(s0.tensor).max()
    np.testing.assert_allclose(s1.tensor, q @ s0.tensor @ q.T, atol=1e-12 * scale)
    np.testing.assert_allclose(s1.per_floe, q @ s0.per_floe @ q.T, atol=1e-12 * scale)
    assert s1.pressure == pytest.approx(s0.pressure, rel=1e-10, abs=1e-12 * scale)
    assert s1.shear == pytest.approx(s0.shear, rel=1e-10)


def test_branch_vectors_span_the_centres():
    """For Hertz contacts and geometric ones, b_i − b_j = x_j − x_i (minimum
    image) to rounding, and the contact point lies r_i − δ/2 from i."""
    pos, box, a = square_lattice(4)
    _, c = _hertz_lattice(pos, box)
    g = contacts_within(pos, np.full(len(pos), R), box, gap=0.0)
    for t in (c, g):
        d = box.minimum_image(pos[t.j] - pos[t.i])
        np.testing.assert_allclose(t.branch_i - t.branch_j, d, atol=1e-12)
        np.testing.assert_allclose(np.hypot(*t.branch_i.T), R - 0.5 * t.overlap, rtol=1e-12)
    assert len(g) == len(c)


# -- the ice within a disc (HertzSimulation.local_ice) ---------------------------

def _nearest_image(d, box):
    """Displacements (K, 2) replaced by the shortest of their nine periodic
    images (a search, not the floor formula of the engine)."""
    shifts = np.array([(i * box.lx, j * box.ly) for i in (-1, 0, 1) for j in (-1, 0, 1)])
    cand = d[:, None, :] + shifts[None, :, :]
    best = np.argmin(np.hypot(cand[..., 0], cand[..., 1]), axis=1)
    return cand[np.arange(len(d)), best]


def test_local_ice_of_a_square_lattice():
    """A disc of radius 1.3 a around a floe of the square lattice (cell a)
    holds the floe, its 4 neighbours at a (the next ones lie at 1.41 a) and
    the 12 contact points at a/2 and 1.12 a (the next at 1.5 a), 6 along x
    and 6 along y: σ_xx = σ_yy = 6 F a / (π (1.3 a)²), σ_xy = 0. Around the
    floe at a corner of the periodic box the neighbours are images across
    its edges (stress to STRESS_RTOL, the counts exact)."""
    pos, box, a = square_lattice()
    sim, c = _hertz_lattice(pos, box)
    f = float(c.normal_force.mean())
    reach = 1.3 * a
    want = 6.0 * f * a / (math.pi * reach ** 2)
    for centre in (pos[14], pos[0]):
        ice = sim.local_ice(centre, reach)
        assert (ice.n_floes, ice.n_contacts) == (5, 12)
        assert ice.floe_area == pytest.approx(5 * math.pi * R ** 2, rel=1e-12)
        assert ice.area == pytest.approx(math.pi * reach ** 2, rel=1e-12)
        assert ice.stress[0, 0] == pytest.approx(want, rel=STRESS_RTOL)
        assert ice.stress[1, 1] == pytest.approx(want, rel=STRESS_RTOL)
        assert abs(ice.stress[0, 1]) < STRESS_RTOL * want
        assert abs(ice.stress[1, 0]) < STRESS_RTOL * want
        assert ice.pressure == pytest.approx(want, rel=STRESS_RTOL)
    # a disc between the floes, smaller than the gap to any contact point
    ice = sim.local_ice(pos[14] + 0.5 * a, 0.2 * a)
    assert (ice.n_floes, ice.n_contacts, ice.pressure) == (0, 0, 0.0)


def test_local_ice_matches_the_contact_table():
    """In a compressed, moving periodic field, the floes, contacts and
    stress within discs at random points equal those picked from the
    engine's Contacts table with NumPy: centres and contact points within
    the radius (nearest periodic image) and −Σ l ⊗ F / (π R²) over them."""
    rng = np.random.default_rng(5)
    # a hexagonal lattice squeezed by 2 %, its floes of radii R ± 1 % shifted
    # by ~0.01 R and moving: unequal normal forces and tangential ones
    pos, box, a = hexagonal_lattice(12, 12)
    pos = pos * 0.98 + rng.normal(0.0, 0.01 * R, pos.shape)
    box = PeriodicBox(box.lx * 0.98, box.ly * 0.98)
    n = len(pos)
    field = FloeField(np.mod(pos, [box.lx, box.ly]), rng.uniform(0.99 * R, 1.01 * R, n),
                      thickness=1.0, velocities=rng.normal(0.0, 0.01, (n, 2)))
    sim = HertzSimulation(field, box, HERMAN2013.contact, None, dt=1e-4, allow_overlap=True)
    sim.step(20)
    c = sim.contacts()
    assert len(c) > 2 * n and np.ptp(c.normal_force) > 0.1 * c.normal_force.max()
    assert np.abs(c.tangential_force).max() > 0.0
    r = sim.radii
    for _ in range(6):
        centre = rng.uniform(0.0, 1.0, 2) * [sim.box.lx, sim.box.ly]
        reach = float(rng.uniform(0.1, 0.45) * min(sim.box.lx, sim.box.ly))
        d = _nearest_image(sim.positions - centre, sim.box)
        near = np.hypot(d[:, 0], d[:, 1]) < reach
        q = _nearest_image(c.contact_point - centre, sim.box)
        inside = np.hypot(q[:, 0], q[:, 1]) < reach
        arm = (c.branch_i - c.branch_j)[inside]
        tensor = -(arm.T @ c.force[inside]) / (math.pi * reach ** 2)
        ice = sim.local_ice(centre, reach)
        assert ice.n_floes == int(near.sum()) and ice.n_contacts == int(inside.sum())
        assert ice.n_contacts > 0
        # 1e-12: the same few hundred terms summed in another order
        assert ice.floe_area == pytest.approx(math.pi * np.sum(r[near] ** 2), rel=1e-12)
        np.testing.assert_allclose(ice.stress, tensor, rtol=0.0,
                                   atol=1e-12 * np.abs(tensor).max())


def test_local_ice_refuses_bad_input():
    pos, box, _ = square_lattice(4)
    sim, _ = _hertz_lattice(pos, box)
    for centre in ((0.0, float("nan")), (1.0,), "xy", None):
        with pytest.raises(ValueError, match="centre"):
            sim.local_ice(centre, 1.0)
    for radius in (0.0, -1.0, float("inf")):
        with pytest.raises(ValueError, match="radius"):
            sim.local_ice((1.0, 1.0), radius)


# -- hard discs: geometric contacts and the collision virial ------------------------

def _gas(seed=3, n=200, log=True):
    rng = np.random.default_rng(seed)
    g = (np.arange(int(math.sqrt(n))) + 0.5) * 3.0
    x, y = np.meshgrid(g, g)
    pos = np.column_stack([x.ravel(), y.ravel()])
    field = FloeField(pos, np.full(len(pos), 1.0), thickness=1.0,
                      velocities=rng.normal(0, 1.0, (len(pos), 2)))
    return HardDiskSimulation(field, PeriodicBox(3.0 * len(g)), restitution=0.9,
                              log_collisions=log)


def test_collision_stress_equals_the_engine_virial():
    """The collision virial rebuilt from the log, Σ (r_i + r_j) n ⊗ J / (S T),
    equals the engine's own accumulated virial (the contact part of
    ``stress()``) to 1e-10, and its per-floe parts add up to it."""
    sim = _gas()
    sim.advance(5.0)
    assert sim.collision_count > 500
    s = sim.contact_stress()
    a = sim._acc
    HK.accumulate(sim.time, a)
    A = HK.Acc
    virial = np.array([[a[A.WXX], a[A.WXY]], [a[A.WYX], a[A.WYY]]])
    virial /= sim.time * sim.L ** 2
    np.testing.assert_allclose(s.tensor, virial, rtol=1e-10)
    np.testing.assert_allclose(s.per_floe.sum(axis=0), s.tensor, rtol=1e-10,
                               atol=1e-12 * np.abs(s.tensor).max())
    assert s.pressure > 0 and s.area == pytest.approx(sim.L ** 2)
    # the same function on the log directly
    s2 = collision_stress(sim.collision_log, sim.radii, sim.L ** 2, sim.time)
    np.testing.assert_allclose(s2.tensor, s.tensor, rtol=1e-14)
    # a new window after clearing the log
    sim.clear_collision_log()
    with pytest.raises(ValueError, match="window"):
        sim.contact_stress()


def test_hard_disc_contacts_are_near_neighbours():
    """Hard-disc contacts are the pairs closer than the gap: on a square
    lattice with edge gap 1 m, gap = 0.9 m finds none and 1.1 m finds the
    four neighbours of every floe (Z_c = 4, Z_a = 0)."""
    sim = _gas(log=False)
    assert len(sim.contacts(0.9)) == 0
    fab = sim.fabric(1.1)
    assert fab.z_c == pytest.approx(4.0, rel=1e-12)
    assert fab.z_a == pytest.approx(0.0, abs=1e-12)
    with pytest.raises(ValueError, match="log"):
        sim.contact_stress()


# -- bad input ----------------------------------------------------------------------

def test_bad_input_is_refused():
    c, n = _random_contacts(0)
    with pytest.raises(ValueError, match="area"):
        stress(c, 0.0)
    with pytest.raises(ValueError, match="area"):
        stress(c, float("nan"))
    with pytest.raises(ValueError, match="n_floes"):
        fabric(c, -1)
    with pytest.raises(ValueError, match="indices"):
        fabric(c, 3)                                # indices beyond n_floes
    bad = Contacts(c.i, c.j[:-1], c.normal, c.overlap, c.normal_force, c.tangential_force,
                   c.force, c.contact_point, c.branch_i, c.branch_j)
    with pytest.raises(ValueError, match="equal length"):
        fabric(bad, n)
    nan_force = c.force.copy()
    nan_force[3, 0] = np.nan
    bad = Contacts(c.i, c.j, c.normal, c.overlap, c.normal_force, c.tangential_force,
                   nan_force, c.contact_point, c.branch_i, c.branch_j)
    with pytest.raises(ValueError, match="NaN"):
        stress(bad, 1.0)
    bad = Contacts(c.i, c.j, c.normal[:-1], c.overlap, c.normal_force, c.tangential_force,
                   c.force, c.contact_point, c.branch_i, c.branch_j)
    with pytest.raises(ValueError, match="shape"):
        fabric(bad, n)
    with pytest.raises(ValueError, match="Contacts"):
        fabric(np.zeros((3, 2)), 3)
    pos = np.zeros((3, 2))
    with pytest.raises(ValueError, match="radii"):
        contacts_within(pos, np.ones(2), PeriodicBox(10.0), 0.1)
    with pytest.raises(ValueError, match="radii"):
        contacts_within(pos, -np.ones(3), PeriodicBox(10.0), 0.1)
    pos[1, 0] = np.nan
    with pytest.raises(ValueError, match="NaN"):
        contacts_within(pos, np.ones(3), PeriodicBox(10.0), 0.1)
    with pytest.raises(ValueError, match="max_gap"):
        near_pairs(np.zeros((3, 2)), np.ones(3), PeriodicBox(10.0), -0.1)
    with pytest.raises(ValueError, match="half"):
        near_pairs(np.zeros((3, 2)), np.ones(3), PeriodicBox(10.0), 3.5)
    with pytest.raises(ValueError, match="duration"):
        collision_stress(c, np.ones(n), 1.0, 0.0)
