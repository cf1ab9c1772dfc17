"""Jammed packings: FIRE relaxation against exact lattice energies and the
jamming concentration against O'Hern et al. (2003)."""
import math

import numpy as np
import pytest

from physics import FloeField, HertzSimulation, PeriodicBox, WalledBox, place_floes
from physics.jamming import compress_floes, jamming_concentration, relax_floes
from physics.observables import contacts_within, fabric
from physics.params import HERMAN2013

PHI_HEX = math.pi / (2.0 * math.sqrt(3.0))      # close packing of equal discs


def hex_crystal(nx, ny, concentration, r=1.0):
    """Triangular lattice of nx × ny equal discs (ny even) at this concentration."""
    a = 2.0 * r * math.sqrt(PHI_HEX / concentration)         # lattice spacing
    i, j = np.meshgrid(np.arange(nx), np.arange(ny), indexing="ij")
    x = (i + 0.5 * (j % 2)) * a
    y = j * a * math.sqrt(3.0) / 2.0
    pos = np.stack([x.ravel(), y.ravel()], axis=1)
    return pos, np.full(nx * ny, r), PeriodicBox(nx * a, ny * a * math.sqrt(3.0) / 2.0), a


def hex_energy_per_floe(a, r=1.0):
    """Six contacts a floe, each shared: 3 (2/5) √R* δ^{5/2}, R* = r/2, δ = 2r − a."""
    delta = 2.0 * r - a
    return 3.0 * 0.4 * math.sqrt(0.5 * r) * delta ** 2.5


def bidisperse(n, seed, concentration=0.75):
    """Half the discs of radius 0.5, half 0.7 (O'Hern's 1:1.4 mixture), placed at random."""
    r = np.where(np.arange(n) < n // 2, 0.5, 0.7)
    box = PeriodicBox(math.sqrt(math.pi * np.sum(r ** 2) / concentration))
    pos = place_floes(r, box, np.random.default_rng(seed))
    return FloeField(pos, r, 1.0, np.zeros((n, 2)), density=910.0), box


def test_two_overlapping_discs_separate():
    pos = np.array([[10.0, 10.0], [11.5, 10.0]])
    res = relax_floes(pos, np.array([1.0, 1.0]), PeriodicBox(40.0))
    assert res.status == "unjammed" and not res.jammed
    d = np.linalg.norm(res.positions[1] - res.positions[0])
    assert 2.0 - 1e-6 < d < 2.1                                 # no overlap left, still close
    assert res.positions.mean(axis=0) == pytest.approx([10.75, 10.0], abs=1e-9)  # no drift


@pytest.mark.parametrize("concentration", [0.92, 0.95])
def test_compressed_hex_crystal_has_the_lattice_energy(concentration):
    pos, r, box, a = hex_crystal(8, 8, concentration)
    res = relax_floes(pos, r, box)
    assert res.status == "balanced" and res.iterations == 0     # in balance by symmetry
    assert res.contacts_per_floe == pytest.approx(6.0)
    assert res.energy_per_floe == pytest.approx(hex_energy_per_floe(a), rel=1e-12)


def test_perturbed_hex_crystal_relaxes_back():
    pos, r, box, a = hex_crystal(8, 8, 0.93)
    rng = np.random.default_rng(3)
    res = relax_floes(pos + rng.normal(0.0, 0.02, pos.shape), r, box, force_tol=1e-6)
    assert res.status == "balanced"
    assert res.energy_per_floe == pytest.approx(hex_energy_per_floe(a), rel=1e-6)
    assert res.contacts_per_floe == pytest.approx(6.0)


def test_jamming_concentration_of_the_bidisperse_mixture():
    """O'Hern et al. (2003): A_J = 0.842 for 50:50 discs of radius ratio 1.4
    (N → ∞; at N = 200 single packings spread by about ±0.005). The jammed
    packing is isostatic: non-rattlers have Z ≈ 2d = 4."""
    found = []
    for seed in range(3):
        field, box = bidisperse(200, seed)
        res = jamming_concentration(field, box, tolerance=5e-4)
        found.append(res.concentration)
        assert res.uncertainty <= 5e-4
        assert res.jammed_result.jammed and res.jammed_result.max_overlap < 0.01
        jam = res.jammed_field
        z = fabric(contacts_within(jam.positions, jam.radii, res.jammed_box, 0.0), jam.n).z_c
        assert 3.7 < z < 4.5
        assert not relax_floes(res.unjammed_field.positions, jam.radii, res.unjammed_box).jammed
    assert np.mean(found) == pytest.approx(0.842, abs=0.01)
    assert np.ptp(found) < 0.02


def test_compress_below_jamming_gives_no_overlap():
    field, box = bidisperse(100, 5, concentration=0.6)
    out, new_box, res = compress_floes(field, box, 0.78, increment=0.02)
    assert out.total_area / new_box.area == pytest.approx(0.78, rel=1e-12)
    assert res.status == "unjammed" and res.max_overlap < 1e-5
    assert np.all(out.velocities == 0.0)


def test_compress_above_jamming_is_in_force_balance_in_the_engine():
    """The jammed packing is an equilibrium of the engine's own Hertz law:
    the net contact force on every floe is small against the mean contact
    force, and the floes stay put under damped dynamics."""
    field, box = bidisperse(100, 6)
    field = FloeField(field.positions, 20.0 * field.radii, 1.0, field.velocities, density=910.0)
    box = PeriodicBox(20.0 * box.lx)
    jam, jam_box, res = compress_floes(field, box, 0.87, increment=0.02, force_tol=1e-5)
    assert res.status == "balanced"
    sim = HertzSimulation(jam, jam_box, HERMAN2013.contact, None, dt=0.002, allow_overlap=True)
    forces, _ = sim.contact_forces()
    c = sim.contacts()
    assert np.abs(forces).max() < 1e-4 * np.abs(c.normal_force).mean()
    sim.step(500)
    assert np.abs(sim.positions - sim.box.wrap(jam.positions)).max() < 1e-6 * jam.radii.mean()
    assert sim.contact_stress().pressure > 0.0


def test_same_input_same_packing():
    field, box = bidisperse(60, 2)
    a = compress_floes(field, box, 0.86, increment=0.02)
    b = compress_floes(field, box, 0.86, increment=0.02)
    assert np.array_equal(a[0].positions, b[0].positions)


@pytest.mark.parametrize("bad, match", [
    (dict(box=WalledBox(30.0)), "periodic"),
    (dict(concentration=1.0), "concentration"),
    (dict(increment=0.0), "increment"),
    (dict(frozen=True), "frozen"),
])
def test_bad_input(bad, match):
    field, box = bidisperse(40, 1, concentration=0.5)
    if bad.get("frozen"):
        frozen = np.zeros(field.n, dtype=bool)
        frozen[0] = True
        field = FloeField(field.positions, field.radii, 1.0, field.velocities, density=910.0,
                          frozen=frozen)
    with pytest.raises(ValueError, match=match):
        compress_floes(field, bad.get("box", box), bad.get("concentration", 0.6),
                       increment=bad.get("increment", 0.01))


def test_already_jammed_start_is_refused():
    pos, r, box, _ = hex_crystal(6, 6, 0.93)
    field = FloeField(pos, r, 1.0, np.zeros_like(pos), density=910.0)
    with pytest.raises(ValueError, match="already jammed"):
        jamming_concentration(field, box)


def test_relax_rejects_bad_arrays():
    with pytest.raises(ValueError, match="shape"):
        relax_floes(np.zeros((3, 2)), np.ones(4), PeriodicBox(50.0))
    with pytest.raises(ValueError, match="positive"):
        relax_floes(np.zeros((2, 2)), np.array([1.0, -1.0]), PeriodicBox(50.0))
    with pytest.raises(ValueError, match="finite"):
        relax_floes(np.array([[0.0, np.nan], [1.0, 1.0]]), np.ones(2), PeriodicBox(50.0))
    with pytest.raises(ValueError, match="too small"):
        relax_floes(np.zeros((2, 2)), np.array([1.0, 10.0]), PeriodicBox(30.0))
