"""Contract shared by every registered environment: the Gymnasium and
Stable-Baselines3 checkers, determinism, rendering, vectorisation, spaces,
documentation and the end of an episode.

The floe environments are built small (few floes) so that the whole module
runs in seconds once the engines are compiled.
"""
import re
import subprocess
import sys

import gymnasium as gym
import numpy as np
import pytest

import iceenvs
from iceenvs import ENV_IDS
from iceenvs.checks import CHECKS
from small_envs import SMALL

WIND = "iceenvs/WindDrift-v0"
CONVERGENCE = "iceenvs/Convergence-v0"
MIZ = "iceenvs/MarginalIceZone-v0"
CLUSTERING = "iceenvs/FloeClustering-v0"
ITD = "iceenvs/ThicknessDistribution-v0"
NAV = "iceenvs/ShipNavigation-v0"
BESET = "iceenvs/ShipBeset-v0"

FLOE_IDS = (WIND, CONVERGENCE, MIZ, CLUSTERING)

# kwargs that end an episode after 3 steps (Gymnasium's TimeLimit)
THREE_STEPS = {env_id: dict(max_episode_steps=3) for env_id in SMALL}

DOC_SECTIONS = ("Description", "Action Space", "Observation Space", "Rewards",
                "Starting State", "Episode End", "Arguments", "Version History")


def make(env_id, **kwargs):
    return gym.make(env_id, **{**SMALL[env_id], **kwargs})


def actions(space, n, seed=0):
    """``n`` reproducible actions inside ``space``."""
    rng = np.random.default_rng(seed)
    return [rng.uniform(space.low, space.high).astype(space.dtype) for _ in range(n)]


@pytest.fixture
def headless(monkeypatch):
    """No real display or audio device for the "human" render mode."""
    monkeypatch.setenv("SDL_VIDEODRIVER", "dummy")
    monkeypatch.setenv("SDL_AUDIODRIVER", "dummy")


def test_every_id_is_registered_with_its_facts():
    from iceenvs.facts import EnvFacts, env_facts

    for env_id in ENV_IDS:
        assert env_id in gym.registry
        assert isinstance(env_facts(env_id), EnvFacts)
        # its small instance is accepted by its constructor
        gym.make(env_id, **SMALL[env_id]).close()


# -- API checkers ------------------------------------------------------------------------

@pytest.mark.parametrize("check", list(CHECKS))
@pytest.mark.parametrize("env_id", ENV_IDS)
def test_shared_checks(env_id, check, headless):
    """Gymnasium's checker without warnings, determinism, sanitised wild
    actions, the reward contract and facts that agree with the environment
    (:mod:`iceenvs.checks`)."""
    CHECKS[check](env_id)


def test_the_reward_contract_is_held(monkeypatch):
    """check_rewards fails a task whose failure pays outside its bounds, or
    whose rewards leave them."""
    from iceenvs.base import ControlEnv
    from iceenvs.checks import check_rewards

    env_id = "iceenvs/Convergence-v0"
    monkeypatch.setattr(ControlEnv, "failure_reward", -1.0)
    with pytest.raises(AssertionError, match="failure_reward -1.0 is outside"):
        check_rewards(env_id)
    monkeypatch.setattr(ControlEnv, "failure_reward", 0.0)
    monkeypatch.setattr(ControlEnv, "reward_bounds", property(lambda self: (0.0, 1e-9)))
    with pytest.raises(AssertionError, match="is outside reward_bounds"):
        check_rewards(env_id)


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_stable_baselines3_env_checker(env_id):
    sb3_checker = pytest.importorskip("stable_baselines3.common.env_checker")
    env = make(env_id)
    try:
        sb3_checker.check_env(env, warn=True)
    finally:
        env.close()


# -- seeding -------------------------------------------------------------------------------

@pytest.mark.parametrize("env_id", ENV_IDS)
def test_different_seed_different_start(env_id):
    env = make(env_id)
    try:
        first, _ = env.reset(seed=1)
        second, _ = env.reset(seed=2)
    finally:
        env.close()
    assert not np.array_equal(first, second)


# -- rendering -----------------------------------------------------------------------------

@pytest.mark.parametrize("env_id", ENV_IDS)
def test_rgb_array_render_is_an_image(env_id):
    env = make(env_id, render_mode="rgb_array")
    try:
        env.reset(seed=0)
        env.step(env.action_space.sample())
        frame = env.render()
    finally:
        env.close()
    assert isinstance(frame, np.ndarray)
    assert frame.dtype == np.uint8
    assert frame.ndim == 3 and frame.shape[2] == 3
    assert frame.shape[0] > 0 and frame.shape[1] > 0
    assert frame.min() != frame.max(), "the frame is a single colour"


# -- vectorisation ---------------------------------------------------------------------------

# The floe engines run Numba kernels on the OpenMP threading layer, which
# cannot be used again in a child forked after the parent has used it (see
# test_fork_after_floe_env_use_in_parent); workers of the floe envs are
# therefore spawned. The ITD env does not use OpenMP and runs with the
# default (fork) start method.
ASYNC_KWARGS = {env_id: dict(vector_kwargs=dict(context="spawn")) for env_id in FLOE_IDS}
ASYNC_KWARGS[ITD] = {}
ASYNC_KWARGS[NAV] = ASYNC_KWARGS[BESET] = dict(vector_kwargs=dict(context="spawn"))

# every spawned worker pays the interpreter and compiled-kernel start-up (seconds
# each); one Hertz env and the hard-disc env cover both engines
_SAME_AS_WIND_DRIFT = pytest.mark.skip(
    reason="spawning workers is slow; WindDrift-v0 covers the Hertz envs' shared base class")
ASYNC_IDS = [WIND, pytest.param(CONVERGENCE, marks=_SAME_AS_WIND_DRIFT),
             pytest.param(MIZ, marks=_SAME_AS_WIND_DRIFT), CLUSTERING, ITD, NAV,
             pytest.param(BESET, marks=pytest.mark.skip(
                 reason="spawning workers is slow; ShipNavigation-v0 covers the ship envs' "
                        "shared base class"))]


@pytest.mark.parametrize("env_id", ASYNC_IDS)
def test_async_vector_env_resets_and_steps(env_id):
    envs = gym.make_vec(env_id, num_envs=2, vectorization_mode="async", **ASYNC_KWARGS[env_id],
                        **SMALL[env_id])
    try:
        obs, _ = envs.reset(seed=[3, 4])
        assert obs.shape == (2,) + envs.single_observation_space.shape
        assert obs.dtype == np.float32
        assert envs.observation_space.contains(obs)
        assert not np.array_equal(obs[0], obs[1])
        obs, reward, terminated, truncated, _ = envs.step(envs.action_space.sample())
        assert envs.observation_space.contains(obs)
        assert reward.shape == (2,) and np.all(np.isfinite(reward))
        assert terminated.shape == truncated.shape == (2,)
        assert not np.any(terminated)
    finally:
        envs.close()


_FORK_SCRIPT = """
import gymnasium as gym
import iceenvs

env = gym.make("iceenvs/Convergence-v0", n_floes=60)
env.reset(seed=0)
env.close()
envs = gym.make_vec("iceenvs/Convergence-v0", num_envs=2, vectorization_mode="async",
                    n_floes=60)
envs.reset(seed=[3, 4])
envs.step(envs.action_space.sample())
envs.close()
"""


def test_fork_after_floe_env_use_in_parent():
    """Small floe fields never start the OpenMP thread pool, so a process that
    has used a floe env can still fork the workers of an async vector env
    (a forked OpenMP pool aborts the child)."""
    # a fresh interpreter, so that the outcome does not depend on earlier tests
    result = subprocess.run([sys.executable, "-c", _FORK_SCRIPT], capture_output=True,
                            text=True, timeout=120)
    if result.returncode != 0 and "fork()" not in result.stderr:
        raise RuntimeError(f"failed for another reason: {result.stderr[-2000:]}")
    assert result.returncode == 0, result.stderr[-2000:]


# -- spaces and documentation -------------------------------------------------------------

@pytest.mark.parametrize("env_id", ENV_IDS)
def test_observation_space_float32_with_finite_bounds(env_id):
    env = make(env_id)
    try:
        space = env.observation_space
        assert isinstance(space, gym.spaces.Box)
        assert space.dtype == np.float32
        assert np.all(np.isfinite(space.low)) and np.all(np.isfinite(space.high))
        assert np.all(space.low < space.high)
        obs, _ = env.reset(seed=0)
        assert obs.dtype == np.float32 and obs.shape == space.shape
        assert space.contains(obs)
        act = env.action_space
        assert isinstance(act, gym.spaces.Box) and act.dtype == np.float32
        assert np.all(act.low == -1) and np.all(act.high == 1)
    finally:
        env.close()


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_class_docstring_has_every_section(env_id):
    cls = gym.spec(env_id).entry_point
    module, name = cls.split(":")
    doc = getattr(__import__(module, fromlist=[name]), name).__doc__
    assert doc
    missing = [s for s in DOC_SECTIONS if f"## {s}" not in doc]
    assert missing == [], f"{env_id}: docstring lacks {missing}"
    # and in the documented order
    positions = [doc.index(f"## {s}") for s in DOC_SECTIONS]
    assert positions == sorted(positions)


def _doc(env_id) -> str:
    module, name = gym.spec(env_id).entry_point.split(":")
    return getattr(__import__(module, fromlist=[name]), name).__doc__


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_docstring_states_the_size_of_the_default_observation(env_id):
    stated = re.search(r"`Box\(float32\)` of (\d+) entries", _doc(env_id))
    assert stated, f"{env_id}: the Observation Space section names no size"
    env = gym.make(env_id)
    try:
        assert int(stated.group(1)) == env.observation_space.shape[0]
    finally:
        env.close()


def _cells(row: str) -> int:
    """Cells of a Markdown table row; an escaped bar (``\\|``) is text."""
    return len(re.split(r"(?<!\\)\|", row.strip().strip("|")))


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_docstring_tables_keep_their_columns(env_id):
    """A bar in a cell's text (an absolute value, |x|) is escaped, so that
    every row of a table has the header's cells."""
    columns = None
    for line in _doc(env_id).splitlines():
        if not line.lstrip().startswith("|"):
            columns = None
        elif columns is None:
            columns = _cells(line)
        else:
            assert _cells(line) == columns, f"{env_id}: {line.strip()}"


def test_package_docstring_lists_every_id():
    for env_id in ENV_IDS:
        assert env_id in iceenvs.__doc__


# -- episode end ----------------------------------------------------------------------------

@pytest.mark.parametrize("env_id", ENV_IDS)
def test_third_step_truncates(env_id):
    env = make(env_id, **THREE_STEPS[env_id])
    try:
        env.reset(seed=0)
        flags = []
        for a in actions(env.action_space, 3, seed=1):
            _, _, terminated, truncated, info = env.step(a)
            assert "error" not in info, info.get("error")
            flags.append((terminated, truncated))
    finally:
        env.close()
    assert flags == [(False, False), (False, False), (False, True)]


def test_fingerprint_is_repeatable_and_sees_a_change():
    """The behaviour hash of ``python -m iceenvs.checks --fingerprint``: the
    same run hashes the same, a longer one differently."""
    from iceenvs.checks import fingerprint

    once = fingerprint(ITD, seeds=1, steps=2)
    assert fingerprint(ITD, seeds=1, steps=2) == once
    assert fingerprint(ITD, seeds=1, steps=3) != once
