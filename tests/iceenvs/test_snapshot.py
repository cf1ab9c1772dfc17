"""Snapshot and restore (:mod:`iceenvs.snapshots`): a restored episode replays
the same future bit for bit, on every registered id, single and native
vector, across episode ends; the snapshot is a copy; bad input is refused.

Bit-for-bit equality is the right comparison here: the replay runs the same
computation, in the same order, on the same state."""
import copy

import gymnasium as gym
import numpy as np
import pytest

from iceenvs import ENV_IDS
from iceenvs.base import ControlEnv
from iceenvs.facts import env_creator, env_spec
from iceenvs.ship_env import ShipEnv
from iceenvs.snapshots import ROW, Snapshot, episode_attributes
from iceenvs.step import ROW_STATE
from iceenvs.vector import row_info
from tests.small_envs import SMALL

VECTOR_IDS = [i for i in ENV_IDS if env_spec(i).vector_entry_point is not None]
#: steps before the snapshot and after it (an episode end among them)
BEFORE, LATEST, AFTER, END_AT = 10, 60, 14, 6


def same(a, b) -> bool:
    """Bit-for-bit equality of step results (dicts, sequences, arrays, numbers)."""
    if isinstance(a, dict):
        return isinstance(b, dict) and a.keys() == b.keys() and all(same(a[k], b[k]) for k in a)
    if isinstance(a, (list, tuple)):
        return (isinstance(b, (list, tuple)) and len(a) == len(b)
                and all(same(x, y) for x, y in zip(a, b)))
    if isinstance(a, np.ndarray) and a.dtype == object:
        return (isinstance(b, np.ndarray) and b.dtype == object and a.shape == b.shape
                and all(same(x, y) for x, y in zip(a.ravel(), b.ravel())))
    if isinstance(a, np.ndarray):
        return (isinstance(b, np.ndarray) and a.dtype == b.dtype
                and np.array_equal(a, b, equal_nan=a.dtype.kind == "f"))
    if isinstance(a, float) and a != a:
        return isinstance(b, float) and b != b
    return type(a) is type(b) and a == b


def actions(space, n: int, seed: int = 0) -> np.ndarray:
    return np.random.default_rng(seed).uniform(space.low, space.high, (n,) + space.shape)


def play(env, acts) -> list:
    """Step results of ``acts``; at step END_AT (and whenever an episode
    ends) a reset without a seed, whose draw reads the environment's
    generator, and its results."""
    out = []
    for i, a in enumerate(acts):
        result = env.step(a)
        out.append(result)
        if result[2] or i == END_AT:
            out.append(env.reset())
    return out


def touching(info) -> bool | None:
    """Whether the step that gave ``info`` ended with ice in contact: the
    hull with a floe (ship tasks) or floes with floes; None for a task
    without contacts."""
    physics = info["physics"]
    if "hull_pressure" in physics:
        return physics["hull_pressure"] > 0
    if "z_c" in physics:
        return physics["z_c"] > 0
    return None


@pytest.fixture(scope="module", params=ENV_IDS)
def played(request):
    """(env, snapshot, the results after it, the measurement at the
    snapshot, the actions after it, whether it was taken in contact) of a
    small instance of an id, played from a seeded reset to its first step
    that ends in contact (after at least BEFORE steps; at most LATEST)."""
    env = gym.make(request.param, **SMALL[request.param]).unwrapped
    env.reset(seed=7)
    acts = actions(env.action_space, LATEST + AFTER)
    for steps, a in enumerate(acts[:LATEST], 1):
        contact = touching(env.step(a)[4])
        if steps >= BEFORE and contact is not False:
            break
    snap = env.snapshot()
    at = copy.deepcopy(env.last_measurement)
    after = acts[steps:steps + AFTER]
    return env, snap, play(env, after), at, after, contact


def test_a_restored_episode_replays_the_same_future(played):
    env, snap, record, _, acts, _ = played
    for _ in range(2):                          # one snapshot, restored twice
        env.restore(snap)
        assert same(play(env, acts), record)


def test_the_snapshot_is_a_copy_that_later_steps_leave_alone(played):
    env, snap, record, at, _, _ = played
    assert snap.steps >= BEFORE and snap.state[ROW]["steps"] == snap.steps
    assert set(snap.state[ROW]) == set(ROW_STATE)      # the batch's arrays of the episode
    assert same(snap.state[ROW]["prev"], at)
    sim = snap.state.get("sim")
    if sim is not None:                         # the engine's copy is its own
        assert sim is not env.sim and not np.shares_memory(sim.positions, env.sim.positions)


def test_the_snapshot_is_taken_in_contact_and_the_replay_crosses_an_episode_end(played):
    """The replay covers what a snapshot must carry: contacts at the
    snapshot (their history springs; the hull's for the ship tasks), and
    a new episode drawn from the generator."""
    env, snap, record, _, _, contact = played
    assert contact is not False
    resets = [r for r in record if len(r) == 2]
    assert resets and not same(resets[0][0], record[0][0])


def test_a_member_left_out_breaks_the_replay(monkeypatch):
    """The replay test fails where a snapshot misses what an episode
    changes: without the generator, the episode after the reset differs."""
    env_id = ENV_IDS[0]
    env = gym.make(env_id, **SMALL[env_id]).unwrapped
    env.reset(seed=7)
    acts = actions(env.action_space, AFTER)
    monkeypatch.setattr(ControlEnv, "episode_members", tuple(
        n for n in ControlEnv.episode_members if n != "_np_random"))
    snap = env.snapshot()
    record = play(env, acts)
    env.restore(snap)
    assert not same(play(env, acts), record)


def _changed(before, value) -> bool:
    if value is not before[0]:
        return True
    return before[1] is not None and not same(before[1], copy.deepcopy(value))


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_every_member_an_episode_changes_is_listed(env_id):
    """An attribute that a reset and steps rebind or change is an episode
    member (or a cache the environment rebuilds): the snapshot cannot miss
    it."""
    env = gym.make(env_id, **SMALL[env_id]).unwrapped
    kept = {name: (value, copy.deepcopy(value) if isinstance(value, (np.ndarray, list, dict, set))
                   else None) for name, value in vars(env).items()}
    env.reset(seed=1)
    for a in actions(env.action_space, 4):
        env.step(a)
    changed = {name for name, value in vars(env).items()
               if name not in kept or _changed(kept[name], value)}
    members, caches, _ = episode_attributes(type(env))
    assert changed - set(members) - set(caches) == set()
    assert changed & {"sim", "model"}           # the check sees the engine change


def test_a_single_environment_refuses_what_it_cannot_restore():
    ship = next(i for i in ENV_IDS if issubclass(env_creator(i), ShipEnv))
    other = next(i for i in ENV_IDS if i != ship)
    env = gym.make(ship, **SMALL[ship]).unwrapped
    with pytest.raises(RuntimeError, match="reset"):
        env.snapshot()
    donor = gym.make(ship, **SMALL[ship]).unwrapped
    donor.reset(seed=0)
    snap = donor.snapshot()
    with pytest.raises(RuntimeError, match="reset"):
        env.restore(snap)
    env.reset(seed=1)
    with pytest.raises(TypeError, match="Snapshot"):
        env.restore({"sim": None})
    stranger = gym.make(other, **SMALL[other]).unwrapped
    stranger.reset(seed=0)
    with pytest.raises(ValueError, match="cannot be restored"):
        env.restore(stranger.snapshot())
    wider = gym.make(ship, **{**SMALL[ship], "width": 250.0}).unwrapped
    wider.reset(seed=0)
    with pytest.raises(ValueError, match="width"):
        env.restore(wider.snapshot())
    env.restore(snap)                           # another env of the same configuration
    assert isinstance(snap, Snapshot) and same(env.last_measurement, donor.last_measurement)


def test_another_environment_of_the_configuration_replays_it():
    env_id = ENV_IDS[0]
    one, two = (gym.make(env_id, **SMALL[env_id]).unwrapped for _ in range(2))
    one.reset(seed=3)
    two.reset(seed=4)
    acts = actions(one.action_space, AFTER)
    snap = one.snapshot()
    record = play(one, acts)
    two.restore(snap)
    assert same(play(two, acts), record)


def vector_rows(envs, acts, k: int) -> list:
    """Sub-environment k's step results (observation, reward, terminated,
    truncated, info) over the batched actions ``acts``."""
    out = []
    for a in acts:
        obs, reward, terminated, truncated, info = envs.step(a)
        out.append((obs[k], reward[k], terminated[k], truncated[k], row_info(info, k)))
    return out


@pytest.mark.parametrize("env_id", VECTOR_IDS)
def test_a_restored_sub_environment_replays_its_future(env_id):
    """Sub-environment 1 restored replays itself, through the autoresets of
    short episodes, while sub-environment 0 goes on; all restored, the whole
    batch replays."""
    envs = gym.make_vec(env_id, num_envs=2, vectorization_mode="vector_entry_point",
                        max_episode_steps=5, **SMALL[env_id])
    envs.reset(seed=11)
    acts = actions(envs.action_space, 3 + 8)
    for a in acts[:3]:
        envs.step(a)
    one, every = envs.snapshot(1), envs.snapshot()
    record = vector_rows(envs, acts[3:], 1)
    assert any(r[3] for r in record)            # an episode ended and was reset
    envs.restore(one, 1)
    assert same(vector_rows(envs, acts[3:], 1), record)
    envs.restore(every)
    batch = [envs.step(a) for a in acts[3:]]
    envs.restore(every)
    assert same([envs.step(a) for a in acts[3:]], batch)
    with pytest.raises(ValueError, match="index"):
        envs.snapshot(2)
    with pytest.raises(ValueError, match="tuple of 2"):
        envs.restore(one)
    envs.close()


def test_a_sub_environment_and_a_single_environment_exchange_snapshots():
    env_id = VECTOR_IDS[-1]
    envs = gym.make_vec(env_id, num_envs=2, vectorization_mode="vector_entry_point",
                        **SMALL[env_id])
    envs.reset(seed=0)
    single = gym.make(env_id, **SMALL[env_id]).unwrapped
    single.reset(seed=5)
    acts = actions(envs.action_space, 6)
    for a in acts[:2]:
        envs.step(a)
    single.restore(envs.snapshot(1))
    record = vector_rows(envs, acts[2:], 1)
    alone = [single.step(a[1]) for a in acts[2:]]
    assert same([(r[0], float(r[1]), bool(r[2])) for r in record], [(o, r, t) for o, r, t, _, _ in alone])
    envs.restore(single.snapshot(), 0)          # and back into a sub-environment
    assert same(envs.envs[0].last_measurement, single.last_measurement)
    envs.close()
