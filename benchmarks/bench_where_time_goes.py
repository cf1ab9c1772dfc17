"""Where the time of a ShipNavigation-v1 step and of PPO on it goes:
``python -m benchmarks.bench_where_time_goes`` (``seaice bench where_time_goes``).

    python -m benchmarks.bench_where_time_goes [--steps 200] [--rounds 5] [--every 20]
                                         [--trajectory-steps N] [--episode-seed 10001]
                                         [--envs 16] [--ppo-steps 4096] [--seed 0]
                                         [--parts substep,ppo]
                                         [--quiet] [--quick] [--json PATH | --no-json]

Each measurement runs in a fresh process on one thread (Numba's and
PyTorch's); ``--quick`` runs them in this process on the small instance.
"""
from __future__ import annotations

import sys
import time

import numba
import numpy as np

from . import harness
from .harness import REPEATS

SUITE = "where_time_goes"
TITLE = "Where the time of a ShipNavigation-v1 step goes"
DESCRIPTION = """
Where the time of a step of `iceenvs/ShipNavigation-v1` goes, and that of
PPO training on it, so that it shows what a faster step must cut. The
substep's parts run on one thread (`numba.set_num_threads(1)`,
`torch.set_num_threads(1)`), in a fresh process, compilation excluded,
every random number seeded.

* **A late engine substep, under each step.** The episode of seed 10001 (its
  default step), the ship sailing straight ahead (a zero action) for 200
  environment steps; then two copies of that state, one under the exact
  step (`free_drift=False`, the floes at rest skipped) and one under the
  fast step (the default, `free_drift=True`), each stepping over one control
  interval per round (`sim.step(n_sub)`, divided by its n_sub substeps).
  Beside the exact step, two of its parts, each in a compiled loop of n_sub
  calls on copies of the same state, with the floes awake and the live
  pairs that the engine's next run finds at its start (`find_awake`,
  `live_pairs` of `physics.hertz_resting`): the kick–drift pass
  (`first_half_awake`, which with half the floes or more awake is
  `first_half` of `physics.hertz_kernels` over all floes, the table says
  which; Δt = 0 so that the state stays put) and the loop over the live
  pairs (`live_pair_forces`; the pairs found apart are skipped as the run
  skips them); the rest is the ship's hull contacts and motion and the
  bookkeeping of the lists. Beside the fast step, the parts it pays once a
  window or once a list, each timed per call in a compiled loop on a copy of
  the state: the classification of the floes into free and engaged
  (`classify`), the closed form that brings the free floes up to date at a
  window's end (`sync_free`, over a whole window) and a rebuild of the
  Verlet list (`rebuild_in_run`), each counted per substep by how often the
  timed rounds called it (the fast step's tally); the rest is the steps of
  the engaged floes themselves (their kick–drift, their live pairs, the
  hull and the guards). Everything takes turns, round after round (five by
  default); each figure is the best round, with the slowest beside it. The
  engines' steps move on by one control interval each round, so that their
  rounds are consecutive intervals of the episode; the parts are timed on
  the state where the rounds begin.
* **Through the episode.** The same episode from its start (its default
  step), every 20 environment steps: the mean wall time of an environment
  step over the last 20, the floes awake, the floes moving faster than
  1 cm/s and the floes in contact, with the floes' water-drag time constant
  m/b (b the engine's linear water-drag coefficient): a floe the ship
  pushes keeps moving for several times m/b.
* **PPO**, in two configurations: the environment's defaults, and its
  documented training configuration (the `env_kwargs` of its entry in
  `agents/hyperparams/ppo.yaml`). Stable-Baselines3 PPO (MLP policy,
  rollouts of 2048 steps over 16 sub-environments, minibatches of 256, 10
  epochs, seed 0) on the native vector environment of ShipNavigation-v1
  (N = 16, observations and rewards normalised by `VecNormalize`, as
  `seaice train` runs it), after one untimed `learn(2048)`: training steps/s
  over a plain `learn(4096)`, then a second `learn(4096)` under cProfile,
  whose cumulative times split the wall time into the engine
  (`physics.hertz.advance_together`), the environments' own Python around
  it (the vector environment's step less the engine), the
  Stable-Baselines3 adapter (`agents.vec`'s `step_wait` less the vector
  step, its `unbatch_info` included), `VecNormalize` (its `step_wait` less
  the adapter's), the policy's forward passes in the rollouts, the rollout
  buffer (adding steps, returns and advantages) and PPO's update
  (`train`); the remainder is the rest of the rollout loop. cProfile's own
  overhead falls on every Python call, so it inflates the Python parts
  somewhat against the compiled engine and PyTorch. Each configuration is
  also trained, unprofiled, with the engine on all the machine's cores
  (PyTorch on one thread, as `seaice train` runs it): the rate a training
  run on this machine sees.
"""

#: the environment whose step is broken down
ENV_ID = "iceenvs/ShipNavigation-v1"
#: the parts of the suite
PARTS = ("substep", "ppo")
#: seed of the episode whose steps are broken down
EPISODE_SEED = 10001
#: a floe moving faster than this counts as moving [m/s]
MOVING = 0.01
#: the full run's sizes
DEFAULTS = dict(steps=200, rounds=REPEATS, every=20, trajectory_steps=None, envs=16,
                rollout=2048, batch_size=256, epochs=10, ppo_warmup=2048, ppo_steps=4096,
                small=False, fresh=True)
#: sizes of ``--quick`` (the small instance, iceenvs.facts.EnvFacts.small,
#: everything in this process)
QUICK = dict(steps=10, rounds=2, every=5, trajectory_steps=20, envs=2, rollout=64,
             batch_size=64, epochs=2, ppo_warmup=64, ppo_steps=64, small=True, fresh=False)


def _kwargs(small: bool) -> dict:
    """``gymnasium.make`` keywords: the small instance, or none."""
    if not small:
        return {}
    from iceenvs.facts import env_facts

    return dict(env_facts(ENV_ID).small)


class _OneThread:
    """Numba and PyTorch on one thread inside the block, as they were after."""

    def __enter__(self):
        self.numba = numba.get_num_threads()
        numba.set_num_threads(1)
        try:
            import torch
        except ImportError:
            self.torch = None
        else:
            self.torch = torch.get_num_threads()
            torch.set_num_threads(1)
        return self

    def __exit__(self, *exc):
        numba.set_num_threads(self.numba)
        if self.torch is not None:
            import torch

            torch.set_num_threads(self.torch)


# ---------------------------------------------------------------------------
# the substep
# ---------------------------------------------------------------------------

def _loops():
    """The compiled loops, made on first use (importing ``physics``)."""
    global _LOOPS
    if "_LOOPS" in globals():
        return _LOOPS
    from physics import hertz_free_drift as F
    from physics import hertz_kernels as K
    from physics import hertz_resting as R

    @numba.njit
    def kicks(floes, ref, drive, kick, awake, path, m):
        s = 0.0
        for _ in range(m):
            s += R.first_half_awake(floes, ref, drive, kick, awake, path)[0]
        return s

    @numba.njit
    def pairs(live, awake, floes, law, box, verlet, dt, path, force, torque, m):
        for _ in range(m):
            R.live_pair_forces(live, awake, floes, law, box, verlet, dt, path, force, torque)

    @numba.njit
    def classify(floes, fbuf, tbuf, table, box, verlet, ship, dt, window, awake, wp, mark,
                 lines, bounds, m):
        for _ in range(m):
            F.classify(floes, fbuf, tbuf, table, box, verlet, ship, dt, dt, window, awake, wp,
                       mark, lines, bounds)
        return awake.count[1]

    @numba.njit
    def sync(floes, fbuf, tbuf, drive, table, box, awake, lines, path, dt, window, ref,
             n_free, m):
        ok = True
        for _ in range(m):
            awake.count[1] = n_free
            ok = F.sync_free(floes, fbuf, tbuf, drive, table, box, awake, lines, path, dt, dt,
                             window, False, ref) and ok
        return ok

    @numba.njit
    def rebuilds(floes, verlet, lx, ly, px, py, ship, dt, m):
        n = 0
        for _ in range(m):
            n += K.rebuild_in_run(floes, verlet, lx, ly, px, py, False, ship, False,
                                  dt).nbr.shape[0]
        return n

    _LOOPS = dict(kicks=kicks, pairs=pairs, classify=classify, sync=sync, rebuilds=rebuilds)
    return _LOOPS


def _make_env(small: bool):
    import gymnasium as gym

    import iceenvs  # noqa: F401  (registers the ids)

    return gym.make(ENV_ID, **_kwargs(small))


def _state(sim) -> dict:
    """Counts of the engine's present state."""
    return dict(floes=int(sim.n_floes), awake=int(sim.n_awake),
                listed_pairs=int(sim.kernel_view().verlet.nbr.size), contacts=len(sim.contacts()),
                time=float(sim.time))


def _fast_parts(sim, loops, n_sub: int):
    """The window-level parts of the fast step on ``sim``'s state (a copy of
    its floes, made here): timed calls of the classification, of the closed
    form of the free floes over a whole window and of a list rebuild, each
    per call [s], and the floes free in the window that begins now."""
    import copy

    from physics import hertz_free_drift as F
    from physics.hertz_resting import Awake

    mine = copy.deepcopy(sim)
    floes, law, wall_law, drive, verlet = mine.kernel_view()
    box = mine.box.kernel_box(mine.time)
    ship = mine.ship.bundle(n_sub)
    nf = floes.pos.shape[0]
    fbuf, tbuf = floes.force.copy(), floes.torque.copy()
    awake = Awake(np.ones(nf, dtype=np.uint8), np.empty(nf, dtype=np.int64),
                    np.empty(nf, dtype=np.int64), np.zeros(3, dtype=np.int64))
    wp = F.new_pairs(verlet)
    mark = np.zeros(nf, dtype=np.uint8)
    lines = np.empty((nf, 6))
    bounds = np.zeros(6)
    table = F.drift_table(floes, drive, mine.dt)
    window = int(mine.free_window)
    path = np.zeros(nf)
    n_free = loops["classify"](floes, fbuf, tbuf, table, box, verlet, ship, mine.dt, window,
                               awake, wp, mark, lines, bounds, 1)
    loops["sync"](floes, fbuf, tbuf, drive, table, box, awake, lines, path, mine.dt, window,
                  verlet.ref, n_free, 1)
    loops["rebuilds"](floes, verlet, box.lengths[0], box.lengths[1], box.periodic_x,
                      box.periodic_y, ship, mine.dt, 1)
    m = 20

    def classify():
        t0 = time.perf_counter()
        loops["classify"](floes, fbuf, tbuf, table, box, verlet, ship, mine.dt, window, awake,
                          wp, mark, lines, bounds, m)
        return (time.perf_counter() - t0) / m

    def sync():
        t0 = time.perf_counter()
        loops["sync"](floes, fbuf, tbuf, drive, table, box, awake, lines, path, mine.dt,
                      window, verlet.ref, n_free, m)
        return (time.perf_counter() - t0) / m

    def rebuild():
        t0 = time.perf_counter()
        loops["rebuilds"](floes, verlet, box.lengths[0], box.lengths[1], box.periodic_x,
                          box.periodic_y, ship, mine.dt, m)
        return (time.perf_counter() - t0) / m

    return [classify, sync, rebuild], int(n_free)


def substep_breakdown(steps: int = 200, rounds: int = REPEATS, seed: int = EPISODE_SEED,
                      small: bool = False) -> dict:
    """Time a late engine substep of ShipNavigation-v1 under each step (see
    :data:`DESCRIPTION`) in this process, on one thread: the state after
    ``steps`` straight-line env steps of episode ``seed`` (the default
    step), then ``rounds`` rounds of the exact step's whole engine step, its
    kick–drift pass and its live-pair loop, and of the fast step's whole
    engine step, its classification, closed form and list rebuild, taking
    turns. Times are per substep, or per call of the window-level parts
    [s]."""
    import copy

    from physics import hertz_kernels as K
    from physics import hertz_resting as R

    with _OneThread():
        env = _make_env(small)
        try:
            env.reset(seed=seed)
            zero = np.zeros(env.action_space.shape, env.action_space.dtype)
            done = 0
            for _ in range(steps):
                _, _, term, trunc, _ = env.step(zero)
                done += 1
                if term or trunc:
                    break
            u = env.unwrapped
            sim = u.sim
            n_sub = int(round(u.control_interval / sim.dt))
            exact = copy.deepcopy(sim)
            exact.free_drift, exact.skip_resting = False, True
            fast = copy.deepcopy(sim)
            fast.free_drift, fast.skip_resting = True, False
            state = _state(exact)

            loops = _loops()
            kicks, pairs_loop = loops["kicks"], loops["pairs"]
            view = exact.kernel_view()
            own = view.floes
            floes = own._replace(pos=own.pos.copy(), vel=own.vel.copy(), omega=own.omega.copy(),
                                 force=own.force.copy(), torque=own.torque.copy())
            verlet = view.verlet._replace(ref=view.verlet.ref.copy(),
                                          hist=view.verlet.hist.copy())
            box = exact.box.kernel_box(exact.time)
            # Δt = 0: the same pass over the same, unchanging state
            kick = K.Kick(0.0, 0.0, box.lengths[0], box.lengths[1], box.periodic_x,
                          box.periodic_y, 1.0, 1.0, 0.0, 0.0)
            path = np.zeros(exact.n_floes)
            drive = view.drive
            # the floes awake and the live pairs as the engine's next run
            # finds them at its start
            awake = R.find_awake(floes, drive, box, verlet)
            n_awake = int(awake.count[0])
            live = R.live_pairs(verlet, awake)
            kicks(floes, verlet.ref, drive, kick, awake, path, 2)     # compile
            pairs_loop(live, awake, floes, view.law, box, verlet, exact.dt, path,
                       floes.force, floes.torque, 1)
            fast_parts, n_free = _fast_parts(fast, loops, n_sub)
            fast.step(n_sub)                                        # untimed: loaded
            tally0 = fast.free_tally.copy()
            rebuilds0 = fast.n_rebuilds

            def whole(which):
                def go():
                    t0 = time.perf_counter()
                    which.step(n_sub)
                    return (time.perf_counter() - t0) / n_sub
                return go

            def kick_pass():
                t0 = time.perf_counter()
                kicks(floes, verlet.ref, drive, kick, awake, path, n_sub)
                return (time.perf_counter() - t0) / n_sub

            def pair_loop():
                t0 = time.perf_counter()
                pairs_loop(live, awake, floes, view.law, box, verlet, exact.dt, path,
                           floes.force, floes.torque, n_sub)
                return (time.perf_counter() - t0) / n_sub

            times = harness.interleaved_rounds(
                [whole(exact), kick_pass, pair_loop, whole(fast), *fast_parts], rounds)
            tally = fast.free_tally - tally0
        finally:
            env.close()
    keys = ("whole", "kick_drift", "live_pairs", "fast_whole", "classify", "sync", "rebuild")
    return dict(seed=seed, env_steps=done, n_sub=n_sub, dt=float(sim.dt),
                control_interval=float(u.control_interval), live_pairs=int(awake.count[2]),
                awake_at_start=n_awake, full_pass=bool(2 * n_awake >= sim.n_floes),
                free_at_window=n_free, window=int(fast.free_window),
                fast_tally=dict(windows=int(tally[0]), substeps=int(tally[3]),
                                engaged_steps=int(tally[2]),
                                rebuilds=int(fast.n_rebuilds - rebuilds0)),
                **state, times=dict(zip(keys, times)))


def episode_trajectory(every: int = 20, max_steps: int | None = None,
                       seed: int = EPISODE_SEED, small: bool = False) -> dict:
    """The episode ``seed`` of ShipNavigation-v1 with a zero action, in this
    process on one thread, to its end (or ``max_steps``): every ``every``
    env steps the mean env step time over the last ``every``, the floes
    awake, moving faster than :data:`MOVING` and in contact; and the floes'
    water-drag time constants m/b."""
    rows = []
    with _OneThread():
        env = _make_env(small)
        try:
            env.reset(seed=seed)
            u = env.unwrapped
            zero = np.zeros(env.action_space.shape, env.action_space.dtype)
            env.step(zero)                  # compilation and first-step work, not timed
            k, spent, block, ended = 1, 0.0, 0, False
            while not ended and (max_steps is None or k < max_steps):
                t0 = time.perf_counter()
                _, _, term, trunc, _ = env.step(zero)
                spent += time.perf_counter() - t0
                k += 1
                block += 1
                ended = bool(term or trunc)
                if k % every == 0 or ended:
                    sim = u.sim
                    speed = np.hypot(*np.asarray(sim.velocities).T)
                    c = sim.contacts()
                    touching = int(np.unique(np.concatenate([c.i, c.j])).size)
                    rows.append(dict(step=k, step_ms=1e3 * spent / block, awake=int(sim.n_awake),
                                     moving=int(np.sum(speed > MOVING)), contacts=len(c),
                                     in_contact=touching,
                                     ship_x=float(u.sim.ship.position[0])))
                    spent, block = 0.0, 0
            sim = u.sim
            m = np.asarray(sim.field.masses, dtype=float)
            b = np.asarray(sim.kernel_view().drive.coefficients[:, 1], dtype=float)
            tau = m[b > 0] / b[b > 0]
        finally:
            env.close()
    return dict(seed=seed, floes=int(sim.n_floes), steps=k, ended=ended, rows=rows,
                tau_median=float(np.median(tau)) if tau.size else None,
                tau_min=float(np.min(tau)) if tau.size else None)


def substep_child(st: dict, seed: int) -> dict:
    """Both substep measurements, in one process."""
    return dict(breakdown=substep_breakdown(st["steps"], st["rounds"], seed, st["small"]),
                trajectory=episode_trajectory(st["every"], st["trajectory_steps"], seed,
                                              st["small"]))


# ---------------------------------------------------------------------------
# PPO
# ---------------------------------------------------------------------------

#: the profiled parts of a PPO run: (file ending, function)
PROFILED = {
    "collect_rollouts": ("stable_baselines3/common/on_policy_algorithm.py", "collect_rollouts"),
    "vec_normalize": ("stable_baselines3/common/vec_env/vec_normalize.py", "step_wait"),
    "adapter": ("agents/vec.py", "step_wait"),
    "unbatch_info": ("agents/vec.py", "unbatch_info"),
    "vector_step": ("iceenvs/vector.py", "step"),
    "engine": ("physics/hertz.py", "advance_together"),
    "policy_forward": ("stable_baselines3/common/policies.py", "forward"),
    "buffer_add": ("stable_baselines3/common/buffers.py", "add"),
    "buffer_returns": ("stable_baselines3/common/buffers.py", "compute_returns_and_advantage"),
    "train": ("stable_baselines3/ppo/ppo.py", "train"),
}
#: the shares of the wall time, in the order of the table
SHARES = ("engine", "env_python", "adapter", "vec_normalize", "policy_forward", "buffer",
          "train", "other")
SHARE_LABELS = {
    "engine": "engine (physics.hertz.advance_together)",
    "env_python": "environments' own Python (vector step less engine)",
    "adapter": "SB3 adapter (agents.vec step_wait less vector step, unbatch_info included)",
    "vec_normalize": "VecNormalize (its step_wait less the adapter's)",
    "policy_forward": "policy forward passes in the rollouts",
    "buffer": "rollout buffer (add, returns and advantages)",
    "train": "PPO update (train)",
    "other": "the rest (rollout loop, callbacks, logging)",
}


def cumulative_times(stats) -> dict:
    """Cumulative seconds of each part of :data:`PROFILED` in a
    :class:`pstats.Stats` (the largest of the functions that match)."""
    out = {}
    for key, (ending, name) in PROFILED.items():
        best = 0.0
        for (filename, _, fn), (_, _, _, ct, _) in stats.stats.items():
            if fn == name and filename.replace("\\", "/").endswith(ending):
                best = max(best, ct)
        out[key] = best
    return out


def shares(cum: dict, wall: float) -> dict:
    """The parts of :data:`SHARES` as fractions of ``wall`` from the
    cumulative times ``cum`` (each difference at least 0)."""
    s = dict(engine=cum["engine"],
             env_python=max(0.0, cum["vector_step"] - cum["engine"]),
             adapter=max(0.0, cum["adapter"] - cum["vector_step"]),
             vec_normalize=max(0.0, cum["vec_normalize"] - cum["adapter"]),
             policy_forward=cum["policy_forward"],
             buffer=cum["buffer_add"] + cum["buffer_returns"],
             train=cum["train"])
    s = {k: min(1.0, v / wall) for k, v in s.items()}
    s["other"] = max(0.0, 1.0 - sum(s.values()))
    return s


def training_kwargs(small: bool = False) -> dict:
    """The environment keywords of ShipNavigation-v1's documented PPO run
    (``env_kwargs`` of its entry in ``agents/hyperparams/ppo.yaml``), over
    the small instance's with ``small``."""
    from agents.train import read_hyperparams

    return {**_kwargs(small), **read_hyperparams("ppo", ENV_ID)["env_kwargs"]}


#: the PPO configurations: the environment's defaults, and its documented
#: training configuration
CONFIGURATIONS = ("default", "training")


def ppo_profile(st: dict, seed: int = 0, configuration: str = "default",
                profile: bool = True) -> dict:
    """PPO on the native vector environment of ShipNavigation-v1 in this
    process (see :data:`DESCRIPTION`), the environment in ``configuration``
    (:data:`CONFIGURATIONS`): training steps/s of a plain ``learn`` and,
    with ``profile`` (on one thread), of a profiled one and its shares."""
    import cProfile
    import pstats

    from stable_baselines3 import PPO

    from agents.envs import make_vec_env

    n = st["envs"]
    n_steps = max(st["rollout"] // n, 2)
    kwargs = training_kwargs(st["small"]) if configuration == "training" else _kwargs(st["small"])
    threads = numba.get_num_threads()
    with _OneThread() if profile else _Threads(threads):
        venv = make_vec_env(ENV_ID, n_envs=n, seed=seed, env_kwargs=kwargs,
                            normalize=dict(norm_obs=True, norm_reward=True),
                            vectorization="native")
        try:
            model = PPO("MlpPolicy", venv, n_steps=n_steps,
                        batch_size=min(st["batch_size"], n_steps * n), n_epochs=st["epochs"],
                        seed=seed, device="cpu")
            model.learn(st["ppo_warmup"])                       # untimed
            before = model.num_timesteps
            t0 = time.perf_counter()
            model.learn(st["ppo_steps"], reset_num_timesteps=False)
            plain = (model.num_timesteps - before) / (time.perf_counter() - t0)
            out = dict(configuration=configuration, env_kwargs=kwargs, envs=n,
                       rollout=n_steps * n, batch_size=min(st["batch_size"], n_steps * n),
                       epochs=st["epochs"], rate=plain, threads=numba.get_num_threads())
            if profile:
                profiler = cProfile.Profile()
                before = model.num_timesteps
                t0 = time.perf_counter()
                profiler.enable()
                model.learn(st["ppo_steps"], reset_num_timesteps=False)
                profiler.disable()
                wall = time.perf_counter() - t0
                steps = model.num_timesteps - before
                cum = cumulative_times(pstats.Stats(profiler))
                out.update(steps=steps, wall=wall, profiled_rate=steps / wall, cumulative=cum,
                           shares=shares(cum, wall))
        finally:
            venv.close()
    return out


class _Threads:
    """PyTorch on one thread and Numba on ``threads`` inside the block."""

    def __init__(self, threads: int):
        self.threads = threads

    def __enter__(self):
        import torch

        self.saved = torch.get_num_threads()
        torch.set_num_threads(1)
        numba.set_num_threads(self.threads)
        return self

    def __exit__(self, *exc):
        import torch

        torch.set_num_threads(self.saved)


# ---------------------------------------------------------------------------
# the record
# ---------------------------------------------------------------------------

def summarise_breakdown(b: dict) -> dict:
    """Best and slowest round of each part; for the exact step the rest
    (whole less the two parts, best over best) and the shares of the whole;
    for the fast step each window-level part per substep (its time per call
    times the calls per substep of the timed rounds: windows, or list
    rebuilds), the rest (the steps themselves) and the shares."""
    t = b["times"]
    best = {k: min(v) for k, v in t.items()}
    best["rest"] = best["whole"] - best["kick_drift"] - best["live_pairs"]
    slowest = {k: max(v) for k, v in t.items()}
    share = {k: best[k] / best["whole"] for k in ("kick_drift", "live_pairs", "rest")}
    out = dict(best=best, slowest=slowest, shares=share)
    tally = b.get("fast_tally")
    if tally and tally["substeps"]:
        per = dict(classify=best["classify"] * tally["windows"] / tally["substeps"],
                   sync=best["sync"] * tally["windows"] / tally["substeps"],
                   rebuild=best["rebuild"] * tally["rebuilds"] / tally["substeps"])
        per["steps"] = best["fast_whole"] - sum(per.values())
        out["fast"] = dict(per_substep=per,
                           shares={k: v / best["fast_whole"] for k, v in per.items()},
                           gain=best["whole"] / best["fast_whole"],
                           engaged=tally["engaged_steps"] / tally["substeps"],
                           steps_per_window=tally["substeps"] / max(tally["windows"], 1))
    return out


def breakdown_tables(b: dict, summary: dict) -> list[dict]:
    """The state and the time per substep of its parts, under each step."""
    rounds = len(b["times"]["whole"])
    state = harness.table(
        f"A late substep: the state after {b['env_steps']} env steps of episode "
        f"{b['seed']}",
        ["floes", "floes awake", "listed pairs", "contacts", "substeps per env step", "Δt [ms]"],
        [[b["floes"], b["awake"], b["listed_pairs"], b["contacts"], b["n_sub"],
          1e3 * b["dt"]]],
        f"Substeps per env step: the control interval ({b['control_interval']:g} s) over Δt.")
    best, slowest, share = summary["best"], summary["slowest"], summary["shares"]
    labels = [("whole", "whole engine step (sim.step(n_sub) / n_sub)"),
              ("kick_drift", "kick–drift pass over all floes (first_half)" if b["full_pass"]
               else f"kick–drift pass over the {b['awake_at_start']} awake floes "
                    f"(first_half_awake)"),
              ("live_pairs", f"live-pair loop (live_pair_forces, {b['live_pairs']} pairs)"),
              ("rest", "rest: hull contacts, the ship's motion, list bookkeeping")]
    rows = []
    for key, label in labels:
        spread = ("–" if key == "rest" else
                  f"+{100 * (slowest[key] / best[key] - 1):.0f} %")
        rows.append([label, 1e6 * best[key], spread,
                     "1" if key == "whole" else f"{100 * share[key]:.1f} %"])
    parts = harness.table(
        f"The exact step (`free_drift=False`): time per substep, one thread (best of "
        f"{rounds} rounds)",
        ["part", "µs per substep", "slowest round", "share of the step"], rows,
        "The rest is the whole less the two parts, best over best, so the three add up to "
        "the whole.")
    tables = [state, parts]
    f = summary.get("fast")
    if f:
        tally = b["fast_tally"]
        per, sh = f["per_substep"], f["shares"]
        rows = [["whole engine step (sim.step(n_sub) / n_sub)", 1e6 * best["fast_whole"],
                 f"+{100 * (slowest['fast_whole'] / best['fast_whole'] - 1):.0f} %", "–", "1"],
                ["classification of a window (classify)", 1e6 * per["classify"],
                 f"+{100 * (slowest['classify'] / best['classify'] - 1):.0f} %",
                 1e6 * best["classify"], f"{100 * sh['classify']:.1f} %"],
                [f"closed form of the free floes ({b['free_at_window']} of {b['floes']}, "
                 f"sync_free)", 1e6 * per["sync"],
                 f"+{100 * (slowest['sync'] / best['sync'] - 1):.0f} %", 1e6 * best["sync"],
                 f"{100 * sh['sync']:.1f} %"],
                ["Verlet list rebuild (rebuild_in_run)", 1e6 * per["rebuild"],
                 f"+{100 * (slowest['rebuild'] / best['rebuild'] - 1):.0f} %",
                 1e6 * best["rebuild"], f"{100 * sh['rebuild']:.1f} %"],
                ["rest: the steps of the engaged floes (kick–drift, live pairs, hull, guards)",
                 1e6 * per["steps"], "–", "–", f"{100 * sh['steps']:.1f} %"]]
        tables.append(harness.table(
            f"The fast step (the default): time per substep, one thread (best of {rounds} "
            f"rounds), {f['gain']:.2f}× faster than the exact step here",
            ["part", "µs per substep", "slowest round", "µs per call", "share of the step"],
            rows,
            f"Over the timed rounds the fast step ran {tally['substeps']} substeps in "
            f"{tally['windows']} windows ({f['steps_per_window']:.1f} substeps each, "
            f"{b['window']} at most) with {tally['rebuilds']} list rebuilds and "
            f"{f['engaged']:.1f} engaged floes per substep. A window-level part per substep is "
            f"its time per call (timed on copies of the state where the rounds begin) times "
            f"its calls per substep; the rest is the whole less them."))
    return tables


def trajectory_table(tr: dict) -> dict:
    """Step time and floes awake, moving and in contact through the episode."""
    rows = [[r["step"], r["step_ms"], r["awake"], r["moving"], r["in_contact"], r["contacts"]]
            for r in tr["rows"]]
    tau = ("–" if tr["tau_median"] is None else
           f"{harness.format_number(tr['tau_median'])} s (shortest "
           f"{harness.format_number(tr['tau_min'])} s)")
    return harness.table(
        f"Through episode {tr['seed']} ({tr['floes']} floes, zero action)",
        ["env step", "ms per env step", "floes awake", f"moving > {100 * MOVING:g} cm/s",
         "floes in contact", "contacts"], rows,
        f"ms per env step: the mean over the steps since the row before. The floes' water-drag "
        f"time constant m/b: median {tau}.")


def ppo_table(p: dict, cores: dict | None = None) -> dict:
    """Training steps/s and the shares of the profiled run of one
    configuration, and its plain rate on every core."""
    rows = [[SHARE_LABELS[k], f"{100 * p['shares'][k]:.1f} %"] for k in SHARES]
    what = ("the environment's defaults" if p["configuration"] == "default" else
            "its documented training configuration (" + ", ".join(
                f"{k}={v}" for k, v in p["env_kwargs"].items()) + ")")
    on_cores = ("" if cores is None else
                f"; {harness.format_number(cores['rate'])} training steps/s with the engine on "
                f"{cores['threads']} threads (PyTorch on one)")
    return harness.table(
        f"PPO on the native vector environment, N = {p['envs']}, {what}: "
        f"{harness.format_number(p['rate'])} training steps/s on one thread",
        ["part", "share of the wall time"], rows,
        f"Rollouts of {p['rollout']} steps, minibatches of {p['batch_size']}, {p['epochs']} "
        f"epochs. Training steps/s of a plain learn of {p['steps']} steps on one thread"
        f"{on_cores}; under cProfile {harness.format_number(p['profiled_rate'])}/s on one "
        f"thread, whose cumulative times give the shares.")


def parse_parts(text: str | None) -> list[str]:
    """The parts of ``--parts`` (``"substep,ppo"``) in the order of
    :data:`PARTS`; ``None``: both.

    Raises
    ------
    ValueError
        If a name is unknown, or none is given.
    """
    return harness.pick_names(text, PARTS, "part")


def run_benchmark(parts, st: dict, episode_seed: int, seed: int, quiet: bool = False) -> dict:
    """Each part of ``parts`` in a fresh process (``st["fresh"]``; else in
    this one, on one thread)."""
    out = {}
    with harness.Progress(len(parts), SUITE, quiet, unit="part") as bar:
        if "substep" in parts:
            if st["fresh"]:
                out["substep"] = harness.spawn_call(substep_child, st, episode_seed, threads=1)
            else:
                out["substep"] = substep_child(st, episode_seed)
            b = out["substep"]["breakdown"]
            out["substep"]["summary"] = s = summarise_breakdown(b)
            bar.log(f"  substep: whole {1e6 * s['best']['whole']:.3g} µs, kick–drift "
                    f"{100 * s['shares']['kick_drift']:.0f} %, live pairs "
                    f"{100 * s['shares']['live_pairs']:.0f} %, rest "
                    f"{100 * s['shares']['rest']:.0f} %")
            bar.advance()
        if "ppo" in parts:
            out["ppo"] = {}
            for configuration in CONFIGURATIONS:
                if st["fresh"]:
                    one = harness.spawn_call(ppo_profile, st, seed, configuration, threads=1)
                    cores = harness.spawn_call(ppo_profile, st, seed, configuration, False)
                else:
                    one = ppo_profile(st, seed, configuration)
                    cores = ppo_profile(st, seed, configuration, False)
                out["ppo"][configuration] = dict(one=one, cores=cores)
                bar.log(f"  PPO, {configuration}: {one['rate']:.3g} training steps/s on one "
                        f"thread (engine {100 * one['shares']['engine']:.0f} %), "
                        f"{cores['rate']:.3g} on {cores['threads']} threads")
            bar.advance()
    return out


def main(argv=None, prog: str | None = None) -> int:
    p = harness.suite_parser(SUITE, TITLE + ": " + DESCRIPTION, prog)
    p.add_argument("--parts", default=None,
                   help="what to measure, comma-separated: " + ", ".join(PARTS)
                        + " (default: both)")
    p.add_argument("--steps", type=int, default=None,
                   help="straight-line env steps before the substep is timed (default 200)")
    p.add_argument("--rounds", type=int, default=None,
                   help=f"rounds of the substep timings (default {DEFAULTS['rounds']})")
    p.add_argument("--every", type=int, default=None,
                   help="env steps between the rows of the episode's table (default 20)")
    p.add_argument("--trajectory-steps", type=int, default=None,
                   help="env steps of the episode's table at most (default: the whole episode)")
    p.add_argument("--episode-seed", type=int, default=EPISODE_SEED,
                   help=f"seed of the episode (default {EPISODE_SEED})")
    p.add_argument("--envs", type=int, default=None,
                   help="sub-environments of the PPO run (default 16)")
    p.add_argument("--ppo-steps", type=int, default=None,
                   help="training steps of each timed learn (default 4096)")
    p.add_argument("--seed", type=int, default=0, help="seed of PPO and its environments")
    args, argv = harness.parse(p, argv)
    st = harness.settings(args, DEFAULTS, QUICK, ("steps", "rounds", "every",
                                                  "trajectory_steps", "envs", "ppo_steps"))
    if min(st["steps"], st["rounds"], st["every"], st["envs"], st["ppo_steps"]) < 1:
        p.error("--steps, --rounds, --every, --envs and --ppo-steps must be at least 1")
    if st["trajectory_steps"] is not None and st["trajectory_steps"] < 1:
        p.error("--trajectory-steps must be at least 1")
    try:
        parts = parse_parts(args.parts)
    except ValueError as exc:
        p.error(str(exc))

    t0 = time.perf_counter()
    out = run_benchmark(parts, st, args.episode_seed, args.seed, args.quiet)
    tables = []
    if "substep" in out:
        tables += breakdown_tables(out["substep"]["breakdown"], out["substep"]["summary"])
        tables.append(trajectory_table(out["substep"]["trajectory"]))
    if "ppo" in out:
        for r in out["ppo"].values():
            tables.append(ppo_table(r["one"], r["cores"]))
    record = harness.make_record(
        SUITE, TITLE, DESCRIPTION, harness.command_line(SUITE, argv), tables,
        dict(parts=parts, settings=st, episode_seed=args.episode_seed, seed=args.seed,
             quick=args.quick, **out),
        time.perf_counter() - t0, machine=harness.machine_info(1 if st["fresh"] else None))
    harness.finish(args, record)
    return 0


if __name__ == "__main__":
    sys.exit(main())
