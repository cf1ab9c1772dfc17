"""Verlet lists against brute force, contact forces against an independent
all-pairs evaluation of the Hertz-Mindlin law, and the parallel kernels
against the serial ones."""
from __future__ import annotations

import math

import numpy as np
import pytest

from physics import (HERMAN2013, ChannelBox, ContactParams, DeformingPeriodicBox, FloeField,
                     Forcing, HertzSimulation, PeriodicBox, WalledBox, make_floe_field,
                     sample_power_law_diameters)
from physics.neighbors import brute_force_pairs, build_pair_list, choose_cell_size, radius_rank

from reference.dem import effective_modulus


def all_pairs_within(pos, radius, box, skin):
    """Every pair (i < j) whose centres are closer than r_i + r_j + skin, with
    minimum-image distances along periodic axes; O(N^2)."""
    d = pos[None, :, :] - pos[:, None, :]
    for axis, (length, periodic) in enumerate(zip((box.lx, box.ly), box.periodic)):
        if periodic:
            d[..., axis] -= length * np.round(d[..., axis] / length)
    dist = np.hypot(d[..., 0], d[..., 1])
    cut = radius[:, None] + radius[None, :] + skin
    i, j = np.nonzero(np.triu(dist < cut, k=1))
    return set(zip(i.tolist(), j.tolist()))


def random_floes(rng, n, box, d_min=1.0, d_max=12.0, alpha=1.8):
    """Power-law radii and uniformly random (overlapping) positions in the box."""
    radius = 0.5 * sample_power_law_diameters(n, alpha, d_min, d_max, rng)
    rng.shuffle(radius)
    pos = rng.random((n, 2)) * np.array([box.lx, box.ly])
    return pos, radius


BOXES = {
    "periodic-square": lambda: PeriodicBox(110.0),
    "periodic-rectangle": lambda: PeriodicBox(150.0, 60.0),
    "channel": lambda: ChannelBox(120.0, 70.0),
    "walled": lambda: WalledBox(90.0, 130.0),
}


@pytest.mark.parametrize("box_name", list(BOXES))
@pytest.mark.parametrize("skin", [0.0, 0.7])
@pytest.mark.parametrize("cell", ["default", "tiny", "whole-box"])
def test_pair_list_equals_brute_force(box_name, skin, cell):
    """build_pair_list finds exactly the pairs closer than r_i + r_j + skin
    (as a set, minimum image on periodic axes), each pair once, owned by the
    floe of higher (radius, index) rank, every slice sorted by partner; for
    cells sized for the median floe, cells smaller than the smallest floe and
    a single cell. brute_force_pairs gives the same set."""
    rng = np.random.default_rng([7, len(box_name), int(10 * skin)])
    box = BOXES[box_name]()
    pos, radius = random_floes(rng, 600, box)
    # floes on the box edges and corners
    pos[:4] = [[0.0, 0.0], [box.lx * (1 - 1e-12), 0.5 * box.ly], [0.5 * box.lx, 0.0],
               [box.lx * (1 - 1e-12), box.ly * (1 - 1e-12)]]
    rank = radius_rank(radius)
    cell_size = {"default": choose_cell_size(radius, box.lx, box.ly, skin),
                 "tiny": 0.4 * radius.min(),
                 "whole-box": max(box.lx, box.ly)}[cell]
    start, nbr = build_pair_list(pos, radius, rank, box.lx, box.ly, box.periodic[0],
                                 box.periodic[1], skin, cell_size)
    owner = np.repeat(np.arange(len(radius)), np.diff(start))
    found = set(zip(np.minimum(owner, nbr).tolist(), np.maximum(owner, nbr).tolist()))
    expected = all_pairs_within(pos, radius, box, skin)
    assert len(expected) > 100
    assert len(found) == len(nbr), "a pair appears twice"
    assert found == expected
    assert np.all(rank[owner] > rank[nbr])
    for i in range(len(radius)):
        assert np.all(np.diff(nbr[start[i]:start[i + 1]]) > 0)
    brute = {tuple(p) for p in brute_force_pairs(pos, radius, box, skin).tolist()}
    assert brute == expected


@pytest.mark.parametrize("box_name", ["periodic-rectangle", "walled"])
def test_pair_list_with_a_skin_per_floe_equals_brute_force(box_name):
    """With a skin per floe (0.3 m for most, 5 m for 25 of the 600) the
    serial and the parallel builder list exactly the pairs closer than
    r_i + r_j + (s_i + s_j)/2, including the wide-skinned floes' partners of
    higher rank; brute_force_pairs agrees. The same skin for every floe as an
    array gives the arrays of the scalar skin."""
    from physics.neighbors import build_pair_list_serial

    rng = np.random.default_rng(23)
    box = BOXES[box_name]()
    pos, radius = random_floes(rng, 600, box)
    rank = radius_rank(radius)
    skins = np.full(600, 0.3)
    wide = rng.choice(600, 25, replace=False)
    skins[wide] = 5.0
    cell = choose_cell_size(radius, box.lx, box.ly, 0.3)
    d = pos[None, :, :] - pos[:, None, :]
    for axis, (length, periodic) in enumerate(zip((box.lx, box.ly), box.periodic)):
        if periodic:
            d[..., axis] -= length * np.round(d[..., axis] / length)
    cut = radius[:, None] + radius[None, :] + 0.5 * (skins[:, None] + skins[None, :])
    i, j = np.nonzero(np.triu(np.hypot(d[..., 0], d[..., 1]) < cut, k=1))
    expected = set(zip(i.tolist(), j.tolist()))
    # the wide skins add pairs that one skin of 0.3 m would not list
    assert len(expected - all_pairs_within(pos, radius, box, 0.3)) > 50
    for build in (build_pair_list, build_pair_list_serial):
        start, nbr = build(pos, radius, rank, box.lx, box.ly, box.periodic[0], box.periodic[1],
                           skins, cell)
        owner = np.repeat(np.arange(600), np.diff(start))
        found = set(zip(np.minimum(owner, nbr).tolist(), np.maximum(owner, nbr).tolist()))
        assert len(found) == len(nbr) and found == expected
        assert np.all(rank[owner] > rank[nbr])
        same = [build(pos, radius, rank, box.lx, box.ly, box.periodic[0], box.periodic[1], skin,
                      cell) for skin in (0.3, np.full(600, 0.3))]
        for a, b in zip(*same):
            np.testing.assert_array_equal(a, b)
    brute = {tuple(p) for p in brute_force_pairs(pos, radius, box, skins).tolist()}
    assert brute == expected


@pytest.mark.parametrize("skin", [0.7, 20.0])
def test_single_pass_build_and_its_fallback_give_the_same_list(skin):
    """The list is built in one scan, each chunk of floes appending to a
    buffer sized from the previous list. With a skin of 20 m the 600 floes
    have 37 partners each, more than the buffers hold when no previous list
    is known: the build falls back to a counting and a filling scan.
    Serial and parallel builders, with and without a size hint, give the
    same arrays, and the brute-force pairs."""
    from physics.neighbors import BLOCK, N_CHUNKS, _append_capacity, build_pair_list_serial

    rng = np.random.default_rng(11)
    box = PeriodicBox(110.0)
    pos, radius = random_floes(rng, 600, box)
    rank = radius_rank(radius)
    cell = choose_cell_size(radius, box.lx, box.ly, skin)
    args = (pos, radius, rank, box.lx, box.ly, True, True, skin, cell)
    ref_start, ref_nbr = build_pair_list_serial(*args)
    counts = np.diff(ref_start)
    overflow = (counts.sum() > _append_capacity(600, 0, 1),
                max(sum(counts[b:b + BLOCK].sum() for b in range(c * BLOCK, 600, N_CHUNKS * BLOCK))
                    for c in range(N_CHUNKS)) > _append_capacity(600, 0, N_CHUNKS))
    assert overflow == ((True, True) if skin > 10 else (False, False))
    for build in (build_pair_list, build_pair_list_serial):
        for hint in (0, len(ref_nbr)):
            start, nbr = build(*args, hint)
            np.testing.assert_array_equal(start, ref_start)
            np.testing.assert_array_equal(nbr, ref_nbr)
    owner = np.repeat(np.arange(600), counts)
    found = set(zip(np.minimum(owner, ref_nbr).tolist(), np.maximum(owner, ref_nbr).tolist()))
    assert found == all_pairs_within(pos, radius, box, skin)


# ---------------------------------------------------------------------------
# Contact forces against an independent all-pairs evaluation
# ---------------------------------------------------------------------------

def reference_contact_forces(floes: FloeField, box, contact: ContactParams):
    """All-pairs Hertz-Mindlin forces and torques with zero tangential history.

    From the contact law (Herman 2013; physics.contact docstring): for floes
    i, j with n the unit vector from i to j, t = k x n, overlap delta > 0,
    R* = r_i r_j/(r_i + r_j), m* = (1/m_i + 1/m_j)^-1 (a frozen floe has
    infinite mass):
      F_n = (4/3) E* sqrt(R*) delta^3/2 + eta v_n,  eta = alpha sqrt(m* (4/3) E* sqrt(R* delta)),
      v_n = (u_i - u_j).n, clipped at 0 (limit_damping);
      F_t = -gamma_t eta v_s (zero spring history), v_s = (u_i - u_j).t + r_i w_i + r_j w_j,
      limited to mu F_n in magnitude (Coulomb);
      force on i = -F_n n + F_t t (opposite on j), torques F_t (r_i - delta/2)
      on i and F_t (r_j - delta/2) on j.
    A rigid wall is a floe of infinite radius and mass with E*_w = E/(1 - nu^2),
    lever arm r - delta. Returns forces (N, 2), torques (N,) and a mask (N,)
    of the floes in a contact whose tangential force is at the Coulomb limit
    with F_n > 0.
    """
    pos = box.wrap(floes.positions)
    r = floes.radii
    vel = floes.velocities
    w = floes.angular_velocities
    inv_m = np.where(floes.frozen, 0.0, 1.0 / floes.masses)
    alpha = contact.damping_alpha
    n_floes = len(r)
    force = np.zeros((n_floes, 2))
    torque = np.zeros(n_floes)
    capped = np.zeros(n_floes, dtype=bool)

    def law(delta, r_eff, m_eff, v_n, v_s, e_star):
        eta = alpha * math.sqrt(m_eff * 4.0 / 3.0 * e_star * math.sqrt(r_eff * delta))
        f_n = 4.0 / 3.0 * e_star * math.sqrt(r_eff) * delta ** 1.5 + eta * v_n
        if contact.limit_damping:
            f_n = max(f_n, 0.0)
        f_t = -contact.tangential_damping * eta * v_s
        limit = contact.friction * abs(f_n)
        at_limit = abs(f_t) > limit
        if at_limit:
            f_t = -math.copysign(limit, v_s)
        return f_n, f_t, at_limit and limit > 0.0

    e_star = effective_modulus(contact)
    for i in range(n_floes):
        for j in range(i + 1, n_floes):
            if inv_m[i] + inv_m[j] == 0.0:
                continue
            d = box.minimum_image(pos[j] - pos[i])
            dist = math.hypot(*d)
            delta = r[i] + r[j] - dist
            if delta <= 0.0:
                continue
            n = d / dist
            t = np.array([-n[1], n[0]])
            du = vel[i] - vel[j]
            f_n, f_t, at_limit = law(delta, r[i] * r[j] / (r[i] + r[j]),
                                     1.0 / (inv_m[i] + inv_m[j]), du @ n,
                                     du @ t + r[i] * w[i] + r[j] * w[j], e_star)
            capped[[i, j]] |= at_limit
            f = -f_n * n + f_t * t
            force[i] += f
            force[j] -= f
            torque[i] += f_t * (r[i] - 0.5 * delta)
            torque[j] += f_t * (r[j] - 0.5 * delta)

    e_wall = contact.elastic_modulus / (1.0 - contact.poisson_ratio ** 2)
    walls = []
    if not box.periodic[0]:
        walls += [(0, np.array([-1.0, 0.0]), lambda p: p[0]),
                  (0, np.array([1.0, 0.0]), lambda p: box.lx - p[0])]
    if not box.periodic[1]:
        walls += [(1, np.array([0.0, -1.0]), lambda p: p[1]),
                  (1, np.array([0.0, 1.0]), lambda p: box.ly - p[1])]
    for i in range(n_floes):
        if inv_m[i] == 0.0:
            continue
        for _, n, distance in walls:
            delta = r[i] - distance(pos[i])
            if delta <= 0.0:
                continue
            t = np.array([-n[1], n[0]])
            f_n, f_t, at_limit = law(delta, r[i], 1.0 / inv_m[i], vel[i] @ n,
                                     vel[i] @ t + r[i] * w[i], e_wall)
            capped[i] |= at_limit
            force[i] += -f_n * n + f_t * t
            torque[i] += f_t * (r[i] - delta)
    return force, torque, capped


def overlapping_state(box, seed, n=200, frozen_fraction=0.1, slip_scale=0.05):
    """Randomly placed (overlapping) floes with random velocities and spins."""
    rng = np.random.default_rng(seed)
    pos, radius = random_floes(rng, n, box, d_min=1.0, d_max=8.0)
    thickness = rng.uniform(0.5, 2.5, n)
    vel = rng.normal(0.0, slip_scale, (n, 2))
    spin = rng.normal(0.0, slip_scale / 4.0, n)
    frozen = rng.random(n) < frozen_fraction
    return FloeField(pos, radius, thickness, vel, spin, frozen=frozen)


FORCE_BOXES = [
    pytest.param("periodic", lambda: PeriodicBox(70.0, 55.0), id="periodic"),
    pytest.param("channel", lambda: ChannelBox(70.0, 50.0), id="channel"),
    pytest.param("walled", lambda: WalledBox(60.0, 60.0), id="walled"),
]


@pytest.mark.parametrize("box_name, make_box", FORCE_BOXES)
@pytest.mark.parametrize("restitution, limit_damping", [(0.5, True), (0.2, True), (0.85, False)])
def test_contact_forces_equal_all_pairs_evaluation(box_name, make_box, restitution,
                                                   limit_damping):
    """On a fresh simulation (zero tangential history) contact_forces()
    equals the all-pairs evaluation of the Hertz-Mindlin law, floe-floe and
    floe-wall, with frozen floes, to 1e-10 of the largest force and torque.
    Friction is high enough here that no contact reaches the Coulomb limit."""
    box = make_box()
    floes = overlapping_state(box, seed=[11, len(box_name), int(100 * restitution)])
    contact = ContactParams(restitution=restitution, friction=1e6, tangential_damping=0.8,
                            limit_damping=limit_damping)
    ref_f, ref_t, capped = reference_contact_forces(floes, box, contact)
    assert not capped.any()
    sim = HertzSimulation(floes, box, contact, None, dt=1e-6, allow_overlap=True)
    force, torque = sim.contact_forces()
    assert np.count_nonzero(np.any(ref_f != 0.0, axis=1)) > 50
    np.testing.assert_allclose(force, ref_f, rtol=0, atol=1e-10 * np.abs(ref_f).max())
    np.testing.assert_allclose(torque, ref_t, rtol=0, atol=1e-10 * np.abs(ref_t).max())


def grazing_pairs():
    """24 separate pairs of touching floes (radii 1-3 m) with overlaps from
    1e-7 to 3e-3 of the smaller radius, approach speeds of 0.01-0.1 m/s,
    slip velocities of 1e-4 to 0.5 m/s either way and random spins, in a
    periodic box of 6 x 4 cells of 20 m: the viscous tangential force of the
    most shallow contacts exceeds mu F_n."""
    rng = np.random.default_rng(14)
    pos, radii, vel = [], [], []
    for k in range(24):
        centre = np.array([20.0 * (k % 6) + 10.0, 20.0 * (k // 6) + 10.0])
        r_i, r_j = rng.uniform(1.0, 3.0, 2)
        delta = min(r_i, r_j) * 10.0 ** rng.uniform(-7.0, -2.5)
        phi = rng.uniform(0.0, 2.0 * np.pi)
        n = np.array([np.cos(phi), np.sin(phi)])
        t = np.array([-n[1], n[0]])
        pos += [centre - r_i * n, centre + (r_j - delta) * n]
        radii += [r_i, r_j]
        slip = rng.choice([-1, 1]) * 10.0 ** rng.uniform(-4.0, -0.3)
        u_rel = rng.uniform(0.01, 0.1) * n + slip * t
        vel += [0.5 * u_rel, -0.5 * u_rel]
    spins = rng.normal(0.0, 0.02, 48)
    return (FloeField(np.array(pos), radii, rng.uniform(0.5, 2.0, 48), np.array(vel), spins),
            PeriodicBox(120.0, 80.0))


def test_grazing_contacts_below_coulomb_limit():
    """Fresh simulation of the grazing pairs with mu = 0.7: for every pair
    whose viscous tangential force stays below mu F_n, contact_forces()
    equals the all-pairs evaluation to 1e-10 of the largest force and torque;
    the set-up has at least 5 pairs on each side of the Coulomb limit
    (tangential damping 1, so that the viscous force alone can reach it)."""
    floes, box = grazing_pairs()
    contact = ContactParams(restitution=0.5, friction=0.7, tangential_damping=1.0)
    ref_f, ref_t, capped = reference_contact_forces(floes, box, contact)
    assert 10 <= np.count_nonzero(capped) <= floes.n - 10
    assert np.all(ref_t != 0.0)
    sim = HertzSimulation(floes, box, contact, None, dt=1e-6)
    force, torque = sim.contact_forces()
    ok = ~capped
    np.testing.assert_allclose(force[ok], ref_f[ok], rtol=0, atol=1e-10 * np.abs(ref_f).max())
    np.testing.assert_allclose(torque[ok], ref_t[ok], rtol=0, atol=1e-10 * np.abs(ref_t).max())


def test_grazing_contacts_at_coulomb_limit():
    """Fresh simulation of the grazing pairs with mu = 0.7 and tangential
    damping 1: the pairs whose viscous tangential force exceeds mu F_n slide,
    |F_t| = mu F_n against the slip, even with zero spring history;
    contact_forces() equals that evaluation to 1e-10 of the largest force
    and torque."""
    floes, box = grazing_pairs()
    contact = ContactParams(restitution=0.5, friction=0.7, tangential_damping=1.0)
    ref_f, ref_t, capped = reference_contact_forces(floes, box, contact)
    sim = HertzSimulation(floes, box, contact, None, dt=1e-6)
    force, torque = sim.contact_forces()
    np.testing.assert_allclose(force[capped], ref_f[capped], rtol=0,
                               atol=1e-10 * np.abs(ref_f).max())
    np.testing.assert_allclose(torque[capped], ref_t[capped], rtol=0,
                               atol=1e-10 * np.abs(ref_t).max())


def test_contacts_are_consistent_with_forces():
    """contacts() lists every touching pair once with unit normals from i to
    j, positive overlaps, and forces whose sums per floe (+ on i, - on j)
    give contact_forces(); branch vectors point from each centre to the same
    contact point, r_i - delta/2 from i along n and r_j - delta/2 from j
    against n."""
    box = PeriodicBox(70.0, 55.0)
    floes = overlapping_state(box, seed=13, frozen_fraction=0.0)
    contact = ContactParams(restitution=0.5, friction=1e6)
    sim = HertzSimulation(floes, box, contact, None, dt=1e-6, allow_overlap=True)
    c = sim.contacts()
    force, _ = sim.contact_forces()
    summed = np.zeros_like(force)
    np.add.at(summed, c.i, c.force)
    np.add.at(summed, c.j, -c.force)
    np.testing.assert_allclose(summed, force, rtol=0, atol=1e-10 * np.abs(force).max())
    expected_pairs = all_pairs_within(box.wrap(floes.positions), floes.radii, box, 0.0)
    got_pairs = set(zip(np.minimum(c.i, c.j).tolist(), np.maximum(c.i, c.j).tolist()))
    assert got_pairs == expected_pairs and len(got_pairs) == len(c)
    assert np.allclose(np.hypot(*c.normal.T), 1.0, rtol=0, atol=1e-14)
    assert np.all(c.overlap > 0.0)
    r = floes.radii
    arm_i = (r[c.i] - 0.5 * c.overlap)[:, None] * c.normal
    arm_j = -(r[c.j] - 0.5 * c.overlap)[:, None] * c.normal
    np.testing.assert_allclose(c.branch_i, arm_i, rtol=0, atol=1e-12)
    np.testing.assert_allclose(c.branch_j, arm_j, rtol=0, atol=1e-12)
    pos = sim.positions
    np.testing.assert_allclose(c.contact_point, pos[c.i] + c.branch_i, rtol=0, atol=1e-9)
    other = pos[c.i] + box.minimum_image(pos[c.j] - pos[c.i]) + c.branch_j
    np.testing.assert_allclose(other, c.contact_point, rtol=0, atol=1e-9)


@pytest.mark.parametrize("box_kind", ["converging", "channel"])
def test_verlet_list_never_misses_a_contact(box_kind):
    """While 150 floes starting at A = 0.8 with random velocities (0.3 m/s)
    collide under wind, in a periodic box converging at dA/dt = 0.05 1/s or in
    a channel, the set of touching pairs reported by contacts() equals the
    brute-force set of overlapping pairs at every one of 60 checks (the list
    is rebuilt before any pair can come into contact unseen)."""
    floes, box = make_floe_field(150, concentration=0.8, alpha=1.8, mean_diameter=4.0, seed=8,
                                 velocity_std=0.3,
                                 box_type=ChannelBox if box_kind == "channel" else PeriodicBox)
    if box_kind == "converging":
        box = DeformingPeriodicBox(box.lx, box.ly, concentration_rate=0.05)
    forcing = Forcing(HERMAN2013.forcing, wind=(5.0, -8.0))
    sim = HertzSimulation(floes, box, HERMAN2013.contact, forcing, 4e-4, impact_speed=1.5)
    seen = 0
    for _ in range(60):
        sim.step(50)
        c = sim.contacts()
        got = set(zip(np.minimum(c.i, c.j).tolist(), np.maximum(c.i, c.j).tolist()))
        assert got == all_pairs_within(sim.positions, floes.radii, box, 0.0)
        seen += len(got)
    assert sim.n_rebuilds > 5 and seen > 100


# ---------------------------------------------------------------------------
# Parallel kernels against serial kernels
# ---------------------------------------------------------------------------

def compressed_state(box_type):
    """300 floes placed at A = 0.8 (alpha = 1.8, mean diameter 8 m), then
    the box and the positions shrunk by 0.15 % so that about 240 pairs
    overlap (by up to a few per cent of the smaller radius)."""
    floes, box = make_floe_field(300, concentration=0.8, alpha=1.8, mean_diameter=8.0, seed=3,
                                 velocity_std=0.05, box_type=box_type)
    s = 0.9985
    rng = np.random.default_rng(4)
    frozen = np.zeros(300, dtype=bool)
    if box_type is ChannelBox:
        frozen = floes.positions[:, 1] < 0.1 * box.ly
    compressed = FloeField(floes.positions * s, floes.radii, floes.thickness, floes.velocities,
                           rng.normal(0.0, 0.01, 300), frozen=frozen)
    return compressed, (box.lx * s, box.ly * s)


@pytest.mark.parametrize("box_type", [PeriodicBox, ChannelBox])
def test_parallel_path_equals_serial_path(box_type):
    """A compressed, overlapping field of 300 floes with Herman (2013)
    contacts and forcing (and, in a channel, walls and frozen floes) run for
    200 steps with parallel=True and parallel=False: positions, velocities
    and spins agree to 1e-9 of their largest magnitude."""
    floes, sides = compressed_state(box_type)
    results = []
    for parallel in (False, True):
        sim = HertzSimulation(floes, box_type(*sides), HERMAN2013.contact,
                              Forcing(HERMAN2013.forcing), 5e-4, impact_speed=1.0,
                              allow_overlap=True, parallel=parallel)
        assert len(sim.contacts()) > 150
        sim.step(200)
        results.append((sim.positions.copy(), sim.velocities.copy(),
                        sim.angular_velocities.copy()))
    for serial, parallel in zip(*results):
        np.testing.assert_allclose(parallel, serial, rtol=0, atol=1e-9 * np.abs(serial).max())
    assert np.abs(results[0][1]).max() > 0.1     # the overlaps did push floes apart


@pytest.mark.parametrize("n_chunks", [2, 3, 5])
def test_pair_chunks_write_disjoint_memory_and_slot_every_cut_pair(n_chunks):
    """The parallel pair loop is race-free: the ranges of floe numbers
    that the chunks write to the force buffer (``chunk_range``) cut
    0 … N−1 into consecutive pieces and hold every owner of their chunk;
    every pair whose partner lies outside its chunk's range (a cut pair)
    has a slot of its own, numbered in the order of the list, and the
    others none; ``gather`` lists each partner's slots in that order
    (which is the order of the chunks), and ``shared`` the partners of
    cut pairs. With the floes numbered in space (as ``make_floe_field``
    does) these are only the few floes along the cuts."""
    from physics.hertz_kernels import VerletList, chunk_range, pair_chunks

    n = 800
    floes, box = make_floe_field(n, concentration=0.6, alpha=1.8, mean_diameter=8.0, seed=5)
    rank = radius_rank(floes.radii)
    start, nbr = build_pair_list(floes.positions, floes.radii, rank, box.lx, box.ly, True, True,
                                 0.4, choose_cell_size(floes.radii, box.lx, box.ly, 0.4))
    verlet = VerletList(start, nbr, np.zeros((nbr.size, 2)), floes.positions, np.array([box.lx, box.ly]),
                        np.zeros(2), 0.4, 1.0, 1.0, np.full(n, 0.4), 0.4, np.zeros(0, dtype=np.int64),
                        np.zeros((0, 2)), np.zeros(0))
    ch = pair_chunks(verlet, n_chunks)
    owners, bounds = ch.owners, ch.bounds
    ranges = [chunk_range(c, owners, bounds, n) for c in range(n_chunks)]
    assert ranges[0][0] == 0 and ranges[-1][1] == n
    assert all(ranges[c][1] == ranges[c + 1][0] for c in range(n_chunks - 1))
    expect = np.full(nbr.size, -1)
    slots = 0
    for c, (lo, hi) in enumerate(ranges):
        for i in owners[bounds[c]:bounds[c + 1]]:
            assert lo <= i < hi
            for p in range(start[i], start[i + 1]):
                if not lo <= nbr[p] < hi:
                    expect[p] = slots
                    slots += 1
    np.testing.assert_array_equal(ch.slot, expect)
    cut = np.flatnonzero(expect >= 0)
    assert ch.cut.shape == (slots, 3) and slots > 0 and not ch.cut.any()
    assert ch.shared.tolist() == sorted(set(nbr[cut].tolist()))
    for k, j in enumerate(ch.shared):
        np.testing.assert_array_equal(ch.gather[ch.first[k]:ch.first[k + 1]],
                                      expect[cut[nbr[cut] == j]])
    assert len(ch.shared) < 0.1 * n
