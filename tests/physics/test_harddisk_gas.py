"""Validation of the event-driven hard-disc engine (:class:`HardDiskSimulation`)
against the statistical mechanics of a hard-disc gas in a periodic square box.

All runs have instantaneous collisions without the TC model
(``collision_duration=0``) and no drag (``forcing=None``); kT = KE / N (2D).

1. Enskog collision rate of an elastic monodisperse gas, η = 0.2 and 0.4:
   ν = 2 n σ g(σ) √(π kT / m) with Henderson's g(σ) = (1 − 7η/16)/(1 − η)²,
   within 2 % (measured: ≲ 0.5 %).
2. Henderson equation of state Z = P A / (N kT) = (1 + η²/8)/(1 − η)²
   within 1 % (measured: ≲ 0.3 %); the stress tensor is symmetric (1e-9),
   isotropic within 5 % of P; pressure() equals the kinetic part plus the
   collision virial rebuilt from the collision log within 1e-9.
3. Elastic conservation over ≥ 1e5 collisions: kinetic energy within 1e-10
   relative, momentum within 1e-10 of Σ m|u|, overlap ≤ 1e-9 of a radius at
   every one of many intermediate times; round-off repairs reported.
4. Haff's law for ε = 0.9: the slope of T^(−1/2) against t for t ≤ 2 t₀
   equals T₀^(−1/2)/t₀, 1/t₀ = (1 − ε²) ν₀ / 4, within 5 %.
5. Reproducibility: same seed, bit-identical trajectory and event counts.
6. Power-law floe sizes (cell list with "big" floes): energy within 1e-10,
   no overlap, big floes present and colliding.
"""
from __future__ import annotations

import numpy as np
import pytest

from physics import FloeField, HardDiskSimulation, PeriodicBox, make_floe_field
from physics.floes import max_overlap, place_floes

RADIUS = 0.5                # m, all floes of the monodisperse gases
SIGMA = 2.0 * RADIUS        # contact distance
THICKNESS = 1.0             # m
EQUILIBRATION = 20          # collisions per floe before any measurement
OVERLAP_TOL = 1e-9          # of the smaller radius
CONSERVATION_TOL = 1e-10    # relative


# ---------------------------------------------------------------------------
# Helpers
# ---------------------------------------------------------------------------

def henderson_g(eta: float) -> float:
    """Contact value of the pair correlation of hard discs (Henderson 1975)."""
    return (1.0 - 7.0 * eta / 16.0) / (1.0 - eta) ** 2


def henderson_z(eta: float) -> float:
    """Compressibility factor of hard discs (Henderson 1975)."""
    return (1.0 + eta ** 2 / 8.0) / (1.0 - eta) ** 2


def monodisperse_field(n: int, eta: float, seed: int):
    """n discs of radius RADIUS at packing fraction eta, Gaussian velocities
    (unit variance per component) with zero total momentum: (field, box)."""
    box = PeriodicBox(np.sqrt(n * np.pi * RADIUS ** 2 / eta))
    rng = np.random.default_rng(seed)
    radii = np.full(n, RADIUS)
    pos = place_floes(radii, box, rng)
    vel = rng.normal(0.0, 1.0, (n, 2))
    vel -= vel.mean(axis=0)
    return FloeField(pos, radii, THICKNESS, vel), box


def free_sim(field: FloeField, box: PeriodicBox, restitution: float = 1.0,
             **kwargs) -> HardDiskSimulation:
    """Hard discs without drag and without the TC model."""
    return HardDiskSimulation(field, box, restitution=restitution, forcing=None,
                              max_velocity_step=1.0, collision_duration=0.0, **kwargs)


def temperature(sim: HardDiskSimulation) -> float:
    """kT = KE / N [J] (2D, translation only)."""
    return sim.kinetic_energy() / sim.n_floes


def enskog_rate(sim: HardDiskSimulation, eta: float) -> float:
    """Enskog collision frequency per floe at the current temperature [1/s]."""
    number_density = sim.n_floes / sim.L ** 2
    return (2.0 * number_density * SIGMA * henderson_g(eta)
            * np.sqrt(np.pi * temperature(sim) / sim.masses[0]))


def equilibrated_gas(n: int, eta: float, seed: int, **kwargs) -> HardDiskSimulation:
    """Elastic monodisperse gas after EQUILIBRATION collisions per floe."""
    sim = free_sim(*monodisperse_field(n, eta, seed), **kwargs)
    sim.advance(EQUILIBRATION / enskog_rate(sim, eta))
    return sim


def conservation_run(sim: HardDiskSimulation, duration: float, chunks: int) -> dict:
    """Advance in ``chunks`` equal pieces; the worst relative energy drift,
    momentum drift (relative to Σ m|u| at the start) and overlap seen."""
    e0 = sim.kinetic_energy()
    p0 = sim.momentum()
    p_scale = float(np.sum(sim.masses * np.hypot(*sim.velocities.T)))
    radii = sim.field.radii
    worst = dict(energy=0.0, momentum=0.0, overlap=max_overlap(sim.positions, radii, sim.box))
    for _ in range(chunks):
        sim.advance(duration / chunks)
        worst["energy"] = max(worst["energy"], abs(sim.kinetic_energy() / e0 - 1.0))
        worst["momentum"] = max(worst["momentum"],
                                float(np.max(np.abs(sim.momentum() - p0))) / p_scale)
        worst["overlap"] = max(worst["overlap"], max_overlap(sim.positions, radii, sim.box))
    return worst


def assert_conserved(worst: dict, sim: HardDiskSimulation) -> None:
    print(f"\n  collisions {sim.collision_count}, energy drift {worst['energy']:.2e}, "
          f"momentum drift {worst['momentum']:.2e}, max overlap {worst['overlap']:.2e}, "
          f"repairs {sim.repairs}, diagnostics {sim.diagnostics}")
    assert worst["energy"] <= CONSERVATION_TOL, (
        f"kinetic energy drift {worst['energy']:.3e}, expected <= {CONSERVATION_TOL:g}")
    assert worst["momentum"] <= CONSERVATION_TOL, (
        f"momentum drift {worst['momentum']:.3e} of sum m|u|, expected <= {CONSERVATION_TOL:g}")
    assert worst["overlap"] <= OVERLAP_TOL, (
        f"max overlap {worst['overlap']:.3e} of a radius, expected <= {OVERLAP_TOL:g}")
    assert sim.diagnostics["energy_lost"] == 0.0, (
        f"elastic run lost {sim.diagnostics['energy_lost']:g} J, expected 0")
    # round-off repairs are legitimate but must stay rare (normally 0)
    assert sim.repairs <= 1e-4 * sim.collision_count, (
        f"{sim.repairs} round-off repairs for {sim.collision_count} collisions, "
        f"expected at most 1e-4 per collision")


# ---------------------------------------------------------------------------
# 1-2. Equilibrium: Enskog collision rate and Henderson equation of state
# ---------------------------------------------------------------------------

N_EQ = 500
MEASURED_COLLISIONS = 500_000


@pytest.fixture(scope="module", params=[0.2, 0.4], ids=lambda eta: f"eta={eta}")
def equilibrium(request):
    """One elastic run per packing fraction: collisions, stress and the
    collision log over a window of MEASURED_COLLISIONS expected collisions."""
    eta = request.param
    sim = equilibrated_gas(N_EQ, eta, seed=2011 + int(100 * eta), log_collisions=True)
    nu = enskog_rate(sim, eta)
    window = 2.0 * MEASURED_COLLISIONS / (N_EQ * nu)
    c0 = sim.collision_count
    sim.reset_stress()
    sim.clear_collision_log()
    sim.advance(window)
    return dict(eta=eta, sim=sim, nu_enskog=nu, window=window,
                collisions=sim.collision_count - c0, stress=sim.stress(),
                pressure=sim.pressure(), kT=temperature(sim), log=sim.collision_log)


def test_enskog_collision_rate(equilibrium):
    eq = equilibrium
    nu = 2.0 * eq["collisions"] / (N_EQ * eq["window"])
    err = nu / eq["nu_enskog"] - 1.0
    print(f"\n  eta={eq['eta']}: {eq['collisions']} collisions, nu = {nu:.5g} /s, "
          f"Enskog {eq['nu_enskog']:.5g} /s, error {100 * err:+.3f} %")
    assert eq["collisions"] >= 0.9 * MEASURED_COLLISIONS
    assert abs(err) < 0.02, (f"collision rate {nu:.5g} /s vs Enskog-Henderson "
                             f"{eq['nu_enskog']:.5g} /s ({100 * err:+.2f} %)")


def test_henderson_equation_of_state(equilibrium):
    eq = equilibrium
    sim, s, p = eq["sim"], eq["stress"], eq["pressure"]
    area = sim.L ** 2
    z = p * area / (N_EQ * eq["kT"])
    z_h = henderson_z(eq["eta"])
    print(f"\n  eta={eq['eta']}: Z = {z:.5f}, Henderson {z_h:.5f}, error "
          f"{100 * (z / z_h - 1):+.3f} %; stress/P = {np.round(s / p, 5).tolist()}")
    assert abs(z / z_h - 1.0) < 0.01, f"Z = {z:.5f}, Henderson {z_h:.5f}"

    # symmetric (central impulses) and isotropic (equilibrium fluid); a sign
    # or factor-2 error in one component would be tens of % of P
    assert abs(s[0, 1] - s[1, 0]) <= 1e-9 * p, f"sigma_xy {s[0, 1]:.6g} != sigma_yx {s[1, 0]:.6g}"
    assert abs(s[0, 0] - s[1, 1]) < 0.05 * p, (
        f"sigma_xx {s[0, 0]:.5g}, sigma_yy {s[1, 1]:.5g}: expected equal within 5 % of P = {p:.5g}")
    assert abs(s[0, 1]) < 0.05 * p, f"sigma_xy {s[0, 1]:.5g}, expected ~0 (< 5 % of P = {p:.5g})"

    # independent rebuild: kinetic part Σ m u²/(2A) = KE/A (constant, elastic)
    # plus the virial Σ r·J/(2 A T) with r = σ n̂ and J ∥ n̂ (equal discs)
    log = eq["log"]
    assert len(log) == eq["collisions"], (
        f"log has {len(log)} entries, expected {eq['collisions']} (the collisions in the window)")
    virial = SIGMA * np.hypot(*log.impulse.T).sum() / (2.0 * area * eq["window"])
    p_rebuilt = N_EQ * eq["kT"] / area + virial
    assert abs(p / p_rebuilt - 1.0) < 1e-9, (
        f"pressure() {p:.12g} vs kinetic + virial from the collision log {p_rebuilt:.12g}")


# ---------------------------------------------------------------------------
# 3. Elastic conservation laws and no overlap
# ---------------------------------------------------------------------------

def test_elastic_conservation_no_overlap():
    eta, target = 0.4, 120_000
    sim = free_sim(*monodisperse_field(500, eta, seed=77))
    duration = 2.0 * target / (sim.n_floes * enskog_rate(sim, eta))
    worst = conservation_run(sim, duration, chunks=200)
    assert sim.collision_count >= 100_000, f"only {sim.collision_count} collisions, expected >= 1e5"
    assert_conserved(worst, sim)


# ---------------------------------------------------------------------------
# 4. Haff's law (homogeneous cooling)
# ---------------------------------------------------------------------------

HAFF_EPS = 0.9
HAFF_ETA = 0.05
HAFF_N = 2000
HAFF_SEEDS = (301, 302, 303)


def haff_slope_ratio(seed: int) -> float:
    """Measured slope of T^(−1/2)(t) over 0 ≤ t ≤ 2 t₀ divided by Haff's
    T₀^(−1/2)/t₀, for an elastically equilibrated gas switched to ε = HAFF_EPS."""
    gas = equilibrated_gas(HAFF_N, HAFF_ETA, seed)
    sim = free_sim(gas.state(), gas.box, restitution=HAFF_EPS)
    t_ref = temperature(sim)
    t0 = 4.0 / ((1.0 - HAFF_EPS ** 2) * enskog_rate(sim, HAFF_ETA))
    times = np.linspace(0.0, 2.0 * t0, 41)
    temps = [t_ref]
    for dt in np.diff(times):
        sim.advance(dt)
        temps.append(temperature(sim))
    slope = np.polyfit(times, np.asarray(temps) ** -0.5, 1)[0]
    overlap = max_overlap(sim.positions, sim.field.radii, sim.box)
    assert overlap <= OVERLAP_TOL, f"overlap {overlap:.3e} in the inelastic run"
    return slope / (t_ref ** -0.5 / t0)


def test_haff_law():
    # Measured: -2.1 % (runs -2.5, -2.5, -1.3 %); over 12 other seeds at this
    # eta and N the mean is -1.4 % (std 0.6 % a run), and -0.6 % for a fit
    # over t <= t0/2 only. The small deficit is physics, not an engine error:
    # the Sonine correction of the homogeneous cooling state (a2 ~ -0.027
    # for eps = 0.9 in 2D) lowers the cooling rate by 3 a2/16 ~ -0.5 %, and
    # velocity correlations that build up during cooling lower the energy
    # lost per collision further (it drifts below (1 - eps^2) kT as t grows,
    # while the collision rate stays at Enskog's).
    ratios = np.array([haff_slope_ratio(seed) for seed in HAFF_SEEDS])
    err = ratios.mean() - 1.0
    print(f"\n  Haff slope / theory per run: {np.round(ratios, 4).tolist()}, "
          f"mean error {100 * err:+.2f} %")
    assert abs(err) < 0.05, (f"slope of T^-1/2 is {ratios.mean():.4f} x Haff's T0^-1/2/t0 "
                             f"(expected 1 within 5 %)")


# ---------------------------------------------------------------------------
# 5. Reproducibility
# ---------------------------------------------------------------------------

def test_same_seed_same_trajectory():
    runs = [equilibrated_gas(500, 0.4, seed) for seed in (5, 5, 6)]
    a, b, other = runs
    expected = EQUILIBRATION * a.n_floes // 2
    assert a.collision_count > 0.8 * expected, (
        f"only {a.collision_count} collisions, expected about {expected}")
    assert np.array_equal(a.positions, b.positions), (
        f"positions differ by up to {np.max(np.abs(a.positions - b.positions)):.3g} m")
    assert np.array_equal(a.velocities, b.velocities), "velocities differ for the same seed"
    assert a.diagnostics == b.diagnostics, f"event counts {a.diagnostics} vs {b.diagnostics}"
    assert not np.array_equal(a.positions, other.positions), "a different seed gave the same run"


# ---------------------------------------------------------------------------
# 6. Power-law floe sizes: cell list with big floes
# ---------------------------------------------------------------------------

def test_power_law_sizes_big_floes():
    field, box = make_floe_field(800, concentration=0.6, alpha=1.5, mean_diameter=2.0, seed=3,
                                 velocity_std=0.05)
    sim = free_sim(field, box, log_collisions=True)
    bigs = sim._cover.floes
    assert bigs.size > 0, "no big floes: the big-floe path of the cell list is not exercised"
    worst = conservation_run(sim, 1000.0, chunks=100)
    log = sim.collision_log
    big_hits = int(np.sum(np.isin(log.i, bigs) | np.isin(log.j, bigs)))
    print(f"\n  {bigs.size} big floes, {big_hits} of {len(log)} collisions involve one")
    assert sim.collision_count > 0, "no collisions"
    assert big_hits > 0, "no collision involved a big floe"
    assert_conserved(worst, sim)
