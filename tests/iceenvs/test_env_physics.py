"""Physical sanity of the floe environments: free drift under steady wind,
the pressure rise at jamming under convergence, wind-driven clustering of
hard discs and the load of onshore wind on a fast-ice edge.

The runs are small (60-300 floes, tens of steps); the Hertz envs use
``stiffness_scale=0.01`` (Young's modulus × 0.01, a time step about 6 times
longer) and long control intervals so that each test takes seconds. Softer
contacts change the overlap at a given load (and so the pressure of jammed
ice at a given concentration), not the balance of wind, drag and Coriolis
forces.
"""
import math

import gymnasium as gym
import numpy as np
import pytest

import iceenvs  # noqa: F401  (registers the ids)
from physics import HERMAN2013, Forcing, steady_drift


def mass_weighted(values, masses):
    values = np.asarray(values, dtype=float)
    return (masses[:, None] * values).sum(axis=0) / masses.sum()


def nearest(records, a):
    """The (A, p) record whose concentration is nearest ``a``."""
    return min(records, key=lambda r: abs(r[0] - a))


# -- WindDrift: steady wind → free drift ---------------------------------------------------

def test_wind_drift_reaches_the_free_drift_of_the_forcing():
    """Under a steady 10 m/s wind along x (action (0.5, 0)) the mass-weighted
    mean ice velocity approaches the mass-weighted analytic free drift of
    Herman (2013) eq 6 with Coriolis, ``physics.steady_drift``.

    The ice spins up with the water-drag time τ = m/b of each floe
    (``Forcing.time_constant``, about 10³ s); the run lasts 4 mass-weighted
    τ, in control intervals of 200 s with ``stiffness_scale=0.01`` to keep it
    fast. Tolerance 15 % (norm of the vector difference over the norm of the
    analytic drift): after 4 τ the start-up transient and the damped inertial
    oscillation have decayed to a few per cent (e^-4 ≈ 2 % for the mean τ,
    more for the slowest floes), and at concentration 0.5 collisions are rare;
    they conserve momentum but move it between floes of different drag per
    mass, a small effect on the mean.
    """
    control_interval = 200.0
    env = gym.make("iceenvs/WindDrift-v0", n_floes=60, concentration=0.5,
                   control_interval=control_interval, stiffness_scale=0.01,
                   max_episode_steps=1000)
    try:
        env.reset(seed=1)
        sim = env.unwrapped.sim
        radii, thickness, masses = sim.radii, sim.field.thickness, sim.masses
        forcing = Forcing(HERMAN2013.forcing, wind=(10.0, 0.0))
        tau = forcing.time_constant(radii, thickness, masses)
        tau_mean = float(np.sum(masses * tau) / masses.sum())
        expected = mass_weighted(steady_drift(forcing, radii, thickness, masses), masses)
        n_steps = math.ceil(4.0 * tau_mean / control_interval)
        for _ in range(n_steps):
            _, _, terminated, truncated, info = env.step(np.array([0.5, 0.0], dtype=np.float32))
            assert not terminated and not truncated, info.get("error")
        assert np.allclose(env.unwrapped.forcing.wind, [10.0, 0.0])
        assert info["time"] >= 3.0 * tau_mean
        phys = info["physics"]
        measured = np.array([phys["u_x"], phys["u_y"]])
        # the observable is the mass-weighted mean velocity of the floes
        assert np.allclose(measured, mass_weighted(sim.velocities, masses), rtol=1e-9, atol=1e-12)
    finally:
        env.close()

    # Coriolis (f > 0) turns the drift to the right of the wind
    assert expected[0] > 0 and expected[1] < 0
    assert measured[1] < 0, f"drift {measured} is not turned to the right of the wind"
    error = float(np.linalg.norm(measured - expected) / np.linalg.norm(expected))
    assert error < 0.15, (f"mean drift {measured} m/s vs free drift {expected} m/s: "
                          f"relative error {error:.3f} after {n_steps * control_interval:g} s "
                          f"(mass-weighted tau {tau_mean:.0f} s)")


# -- Convergence: pressure rises sharply at jamming -----------------------------------------

def test_convergence_pressure_rises_sharply_near_jamming():
    """Constant convergence (action +1: dA/dt = 1 per hour) from A = 0.80:
    the contact pressure stays small until the ice jams and then rises by
    orders of magnitude, faster and faster with A.

    200 floes (smaller samples jam earlier: with 60 floes the jam is at about
    0.83-0.85, leaving no unjammed state at A = 0.85), ``stiffness_scale=0.01``
    for speed, and ``failure_pressure=1e9`` so that the episode does not
    terminate at the default 1e5 N/m, which is passed right after jamming,
    before the rise can be followed up to A = 0.93.
    """
    env = gym.make("iceenvs/Convergence-v0", n_floes=200, control_interval=5.0,
                   stiffness_scale=0.01, failure_pressure=1e9, max_episode_steps=1000)
    records = []
    try:
        _, info = env.reset(seed=0, options={"concentration": 0.80})
        assert info["physics"]["concentration"] == pytest.approx(0.80)
        while True:
            _, _, terminated, truncated, info = env.step(np.array([1.0], dtype=np.float32))
            if "error" in info:
                break
            phys = info["physics"]
            records.append((phys["concentration"], phys["pressure"]))
            if terminated or truncated or phys["concentration"] > 0.93:
                break
    finally:
        env.close()

    a_max, p_max = max(records)
    assert a_max > 0.90, f"the run stopped at A = {a_max:.3f}: {info.get('error')}"
    a85, p85 = nearest(records, 0.85)
    assert abs(a85 - 0.85) < 0.005
    if p85 < 1.0:           # no force network yet at 0.85
        assert p_max > 1e4, f"p = {p_max:.3g} N/m at A = {a_max:.3f}"
    else:
        assert p_max >= 100.0 * p85, (f"p = {p_max:.3g} N/m at A = {a_max:.3f} vs "
                                      f"{p85:.3g} N/m at A = {a85:.3f}")
    # loose ice carries little pressure: below A = 0.83 less than 1 % of the end value
    loose = [p for a, p in records if a <= 0.83]
    assert loose and max(loose) < 0.01 * p_max, f"max p below A = 0.83: {max(loose):.3g} N/m"

    def slope(lo, hi):
        (a0, p0), (a1, p1) = nearest(records, lo), nearest(records, hi)
        return (p1 - p0) / (a1 - a0)

    early = slope(0.82, 0.86)
    late = slope(a_max - 0.02, a_max)
    assert late > early, (f"dp/dA = {late:.3g} N/m over the last 0.02 of A vs {early:.3g} N/m "
                          f"over 0.82-0.86")


# -- FloeClustering: steady wind builds a large cluster -------------------------------------

def _largest_cluster_run(n_steps, concentration=0.85, **kwargs):
    env = gym.make("iceenvs/FloeClustering-v0", n_floes=300, concentration=concentration,
                   control_interval=100.0, max_episode_steps=1000, **kwargs)
    try:
        _, info = env.reset(seed=0)
        fractions = [info["physics"]["largest_cluster"]]
        for _ in range(n_steps):
            _, _, terminated, truncated, info = env.step(np.array([0.5, 0.0], dtype=np.float32))
            assert not terminated and not truncated, info.get("error")
            fractions.append(info["physics"]["largest_cluster"])
    finally:
        env.close()
    return fractions


def test_floe_clustering_wind_grows_the_largest_cluster():
    """At Ā = 0.85 under a steady 10 m/s wind (action (0.5, 0)) the floes
    pack into one large cluster: the largest-cluster fraction over the last
    500 s of 3000 s is well above (by 0.2) its value over the first 500 s.

    The first intervals, not the placement, are the reference: the random
    placement at Ā = 0.85 leaves many floes within 1 cm of each other
    (fractions 0.33-0.74 by seed), which the first 100 s break up (0.24-0.57
    over the first 500 s). Over seeds 0-23 the rise is 0.32-0.65 and the
    late fraction at least 0.81; above the start value it rises by as
    little as 0.08 (seed 1).

    Clusters here are floes closer than 1 cm (``cluster_gap=0.01``, the same
    distance the env uses for contacts): with a gap of 0.5 m every
    floe of the start state already belongs to one cluster at this
    concentration (with 0.1 m, the default, see the test below).
    """
    fractions = _largest_cluster_run(30, cluster_gap=0.01)
    start = fractions[0]
    early, late = float(np.mean(fractions[1:6])), float(np.mean(fractions[-5:]))
    assert 0.0 < start < 0.9
    assert late > early + 0.2, (f"largest-cluster fraction {early:.3f} over the first 500 s, "
                                f"{late:.3f} over the last 500 s of 3000 s: "
                                f"{np.round(fractions, 3).tolist()}")


def test_floe_clustering_default_gap_leaves_room_to_grow():
    """With the default cluster gap (0.1 m) and concentration (0.7) the random
    start is far from one cluster, so steady wind can grow the largest one."""
    fractions = _largest_cluster_run(10, concentration=0.7)
    assert fractions[0] < 0.5
    assert float(np.mean(fractions[-5:])) > fractions[0], np.round(fractions, 3).tolist()


# -- MarginalIceZone: onshore wind loads the fast-ice edge ----------------------------------

def _edge_stress(seed, action, n_steps=8):
    env = gym.make("iceenvs/MarginalIceZone-v0", n_floes=60, control_interval=50.0,
                   stiffness_scale=0.01, max_episode_steps=1000)
    try:
        env.reset(seed=seed)
        stresses = []
        for _ in range(n_steps):
            _, _, terminated, truncated, info = env.step(np.array(action, dtype=np.float32))
            assert not terminated and not truncated, info.get("error")
            stresses.append(info["physics"]["edge_stress"])
        sim = env.unwrapped.sim
        forcing = env.unwrapped.forcing
        mobile = ~sim.frozen
        drag = forcing.coefficients(sim.radii, sim.field.thickness, sim.masses)
        wind_load = drag.wind[mobile].sum() * float(np.hypot(*forcing.wind)) * forcing.wind
        load_per_length = float(np.hypot(*wind_load)) / sim.box.lx
    finally:
        env.close()
    return float(np.mean(stresses[-3:])), load_per_length


def test_marginal_ice_zone_onshore_wind_loads_the_edge():
    """20 m/s wind towards the fast ice (action (1, -0.5), along −y) presses
    the drifting ice onto the edge; the same wind away from it (action
    (1, 0.5)) opens the ice there. After 400 s the edge stress (mean of the
    last 3 steps, averaged over 3 seeds) is larger for onshore wind.

    The mean over seeds is compared because in a channel of 60 floes a
    single large mobile floe can wedge into the fast-ice band and load it
    even under offshore wind (seed 1). Under onshore wind the ice comes to
    rest against the edge, which then carries at most the wind load on the
    drifting floes (Σ a |u_a| u_a per edge length) and, unless floes rest on
    the wall between the fast floes, most of it.
    """
    seeds = (0, 1, 2)
    onshore = [_edge_stress(seed, (1.0, -0.5)) for seed in seeds]
    offshore = [_edge_stress(seed, (1.0, 0.5)) for seed in seeds]
    on = np.mean([s for s, _ in onshore])
    off = np.mean([s for s, _ in offshore])
    assert on > off, f"edge stress onshore {onshore}, offshore {offshore} (N/m, wind load)"
    for stress, load in onshore:
        assert 0.3 * load < stress < 1.2 * load, (f"edge stress {stress:.3g} vs wind load "
                                                  f"{load:.3g} N/m")


def test_convergence_failure_is_absorbing():
    """Breaking the ice (p > failure_pressure) ends the episode with reward 0
    (the failed state is worth nothing, and every reward is >= 0), so a
    policy cannot gain by crushing the ice; the steps before get the plain
    reward."""
    env = gym.make("iceenvs/Convergence-v0", n_floes=100, stiffness_scale=0.01,
                   failure_pressure=1.0, max_episode_steps=400)
    try:
        env.reset(seed=1, options={"concentration": 0.84})
        base = env.unwrapped
        for k in range(1, 401):  # noqa: B007  (k counts the steps after the loop)
            _, reward, terminated, truncated, info = env.step(np.array([1.0], dtype=np.float32))
            assert "error" not in info
            if terminated:
                break
            assert reward == pytest.approx(base.reward(np.array([1.0]), info["physics"]))
            assert 0.0 <= reward <= 1.0
        assert terminated and not truncated and k < 400
        assert info["physics"]["pressure"] > 1.0
        assert reward == 0.0
    finally:
        env.close()
