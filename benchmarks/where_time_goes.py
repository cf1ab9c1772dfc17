"""Where the time of a ShipNavigation-v1 step and of PPO on it goes:
``python -m benchmarks.where_time_goes`` (``seaice bench where_time_goes``).

    python -m benchmarks.where_time_goes [--steps 200] [--rounds 5] [--every 20]
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
PPO training on it, so that it shows what a faster step must cut. Everything
runs on one thread (`numba.set_num_threads(1)`, `torch.set_num_threads(1)`),
in a fresh process per measurement, compilation excluded, every random
number seeded.

* **A late engine substep.** The episode of seed 10001, the ship sailing
  straight ahead (a zero action) for 200 environment steps; then, on that
  state, the engine's own step over one control interval
  (`sim.step(n_sub)`, divided by its n_sub substeps), beside two of its
  parts, each in a compiled loop of n_sub calls on copies of the same
  state, with the floes awake and the live pairs that the engine's next run
  finds at its start (`find_awake`, `live_pairs` of
  `physics.hertz_resting`): the kick–drift pass (`first_half_awake`, which
  with half the floes or more awake is `first_half` of
  `physics.hertz_kernels` over all floes, the table says which; Δt = 0 so
  that the state stays put) and the loop over the live pairs (`live_pair_forces`; the pairs
  found apart are skipped as the run skips them). The rest, the whole
  less the two parts, is the ship's hull contacts and motion and the
  bookkeeping of the lists. The three take turns, round after round (five
  by default); each figure is the best round, with the slowest beside it.
  The engine's step moves on by one control interval each round, so that
  its rounds are consecutive intervals of the episode; the two parts are
  timed on the state where the rounds begin.
* **Through the episode.** The same episode from its start, every 20
  environment steps: the mean wall time of an environment step over the last
  20, the floes awake, the floes moving faster than 1 cm/s and the floes in
  contact, with the floes' water-drag time constant m/b (b the engine's
  linear water-drag coefficient): a floe the ship pushes keeps moving, and
  awake, for several times m/b.
* **PPO.** Stable-Baselines3 PPO (MLP policy, rollouts of 2048 steps over
  16 sub-environments, minibatches of 256, 10 epochs, seed 0) on the native
  vector environment of ShipNavigation-v1 (N = 16, observations and rewards
  normalised by `VecNormalize`, as `seaice train` runs it), after one
  untimed `learn(2048)`: training steps/s over a plain `learn(4096)`, then a
  second `learn(4096)` under cProfile, whose cumulative times split the wall
  time into the engine (`physics.hertz.advance_together`), the
  environments' own Python around it (the vector environment's step less
  the engine), the Stable-Baselines3 adapter (`agents.vec`'s `step_wait`
  less the vector step, its `unbatch_info` included), `VecNormalize` (its
  `step_wait` less the adapter's), the policy's forward passes in the
  rollouts, the rollout buffer (adding steps, returns and advantages) and
  PPO's update (`train`); the remainder is the rest of the rollout loop.
  cProfile's own overhead falls on every Python call, so it inflates the
  Python parts somewhat against the compiled engine and PyTorch.
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
    """The two compiled loops, made on first use (importing ``physics``)."""
    global _KICKS, _PAIRS
    if "_KICKS" in globals():
        return _KICKS, _PAIRS
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

    _KICKS, _PAIRS = kicks, pairs
    return kicks, pairs


def _make_env(small: bool):
    import gymnasium as gym

    import iceenvs  # noqa: F401  (registers the ids)

    return gym.make(ENV_ID, **_kwargs(small))


def _state(sim) -> dict:
    """Counts of the engine's present state."""
    return dict(floes=int(sim.n_floes), awake=int(sim.n_awake),
                listed_pairs=int(sim._verlet.nbr.size), contacts=len(sim.contacts()),
                time=float(sim.time))


def substep_breakdown(steps: int = 200, rounds: int = REPEATS, seed: int = EPISODE_SEED,
                      small: bool = False) -> dict:
    """Time a late engine substep of ShipNavigation-v1 and two of its parts
    (see :data:`DESCRIPTION`) in this process, on one thread: the state
    after ``steps`` straight-line env steps of episode ``seed``, then
    ``rounds`` rounds of the whole engine step, the kick–drift pass and the
    live-pair loop taking turns. Times are per substep [s]."""
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
            state = _state(sim)

            kicks, pairs_loop = _loops()
            floes = sim._floes._replace(pos=sim._pos.copy(), vel=sim._vel.copy(),
                                        omega=sim._omega.copy(), force=sim._force.copy(),
                                        torque=sim._torque.copy())
            verlet = sim._verlet._replace(ref=sim._verlet.ref.copy(),
                                          hist=sim._verlet.hist.copy())
            box = sim.box.kernel_box(sim.time)
            # Δt = 0: the same pass over the same, unchanging state
            kick = K.Kick(0.0, 0.0, box.lengths[0], box.lengths[1], box.periodic_x,
                          box.periodic_y, 1.0, 1.0, 0.0, 0.0)
            path = np.zeros(sim.n_floes)
            drive = sim._drive()
            # the floes awake and the live pairs as the engine's next run
            # finds them at its start
            awake = R.find_awake(floes, drive, box, verlet)
            n_awake = int(awake.count[0])
            live = R.live_pairs(verlet, awake)
            kicks(floes, verlet.ref, drive, kick, awake, path, 2)     # compile
            pairs_loop(live, awake, floes, sim._law, box, verlet, sim.dt, path, floes.force,
                       floes.torque, 1)

            def whole():
                t0 = time.perf_counter()
                sim.step(n_sub)
                return (time.perf_counter() - t0) / n_sub

            def kick_pass():
                t0 = time.perf_counter()
                kicks(floes, verlet.ref, drive, kick, awake, path, n_sub)
                return (time.perf_counter() - t0) / n_sub

            def pair_loop():
                t0 = time.perf_counter()
                pairs_loop(live, awake, floes, sim._law, box, verlet, sim.dt, path,
                           floes.force, floes.torque, n_sub)
                return (time.perf_counter() - t0) / n_sub

            times = harness.interleaved_rounds([whole, kick_pass, pair_loop], rounds)
        finally:
            env.close()
    return dict(seed=seed, env_steps=done, n_sub=n_sub, dt=float(sim.dt),
                control_interval=float(u.control_interval), live_pairs=int(awake.count[2]),
                awake_at_start=n_awake, full_pass=bool(2 * n_awake >= sim.n_floes),
                **state, times=dict(zip(("whole", "kick_drift", "live_pairs"), times)))


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
            b = np.asarray(sim._drag[:, 1], dtype=float)
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


def ppo_profile(st: dict, seed: int = 0) -> dict:
    """PPO on the native vector environment of ShipNavigation-v1 in this
    process, on one thread (see :data:`DESCRIPTION`): training steps/s of a
    plain and of a profiled ``learn``, and the shares of the profiled one."""
    import cProfile
    import pstats

    from stable_baselines3 import PPO

    from agents.envs import make_vec_env

    n = st["envs"]
    n_steps = max(st["rollout"] // n, 2)
    with _OneThread():
        venv = make_vec_env(ENV_ID, n_envs=n, seed=seed, env_kwargs=_kwargs(st["small"]),
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
            profiler = cProfile.Profile()
            before = model.num_timesteps
            t0 = time.perf_counter()
            profiler.enable()
            model.learn(st["ppo_steps"], reset_num_timesteps=False)
            profiler.disable()
            wall = time.perf_counter() - t0
            steps = model.num_timesteps - before
        finally:
            venv.close()
    cum = cumulative_times(pstats.Stats(profiler))
    return dict(envs=n, rollout=n_steps * n, batch_size=min(st["batch_size"], n_steps * n),
                epochs=st["epochs"], steps=steps, wall=wall, rate=plain,
                profiled_rate=steps / wall, cumulative=cum, shares=shares(cum, wall))


# ---------------------------------------------------------------------------
# the record
# ---------------------------------------------------------------------------

def summarise_breakdown(b: dict) -> dict:
    """Best and slowest round of each part, the rest (whole less the two
    parts, best over best) and the shares of the whole."""
    t = b["times"]
    best = {k: min(v) for k, v in t.items()}
    best["rest"] = best["whole"] - best["kick_drift"] - best["live_pairs"]
    slowest = {k: max(v) for k, v in t.items()}
    share = {k: best[k] / best["whole"] for k in ("kick_drift", "live_pairs", "rest")}
    return dict(best=best, slowest=slowest, shares=share)


def breakdown_tables(b: dict, summary: dict) -> list[dict]:
    """The state and the time per substep of its parts."""
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
        f"Time per substep, one thread (best of {rounds} rounds)",
        ["part", "µs per substep", "slowest round", "share of the step"], rows,
        "The rest is the whole less the two parts, best over best, so the three add up to "
        "the whole.")
    return [state, parts]


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


def ppo_table(p: dict) -> dict:
    """Training steps/s and the shares of the profiled run."""
    rows = [[SHARE_LABELS[k], f"{100 * p['shares'][k]:.1f} %"] for k in SHARES]
    return harness.table(
        f"PPO on the native vector environment, N = {p['envs']}: "
        f"{harness.format_number(p['rate'])} training steps/s",
        ["part", "share of the wall time"], rows,
        f"Rollouts of {p['rollout']} steps, minibatches of {p['batch_size']}, {p['epochs']} "
        f"epochs. Training steps/s of a plain learn of {p['steps']} steps; under cProfile "
        f"{harness.format_number(p['profiled_rate'])}/s, whose cumulative times give the "
        f"shares.")


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
            if st["fresh"]:
                out["ppo"] = harness.spawn_call(ppo_profile, st, seed, threads=1)
            else:
                out["ppo"] = ppo_profile(st, seed)
            p = out["ppo"]
            bar.log(f"  PPO: {p['rate']:.3g} training steps/s, engine "
                    f"{100 * p['shares']['engine']:.0f} %, update {100 * p['shares']['train']:.0f} %")
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
        tables.append(ppo_table(out["ppo"]))
    record = harness.make_record(
        SUITE, TITLE, DESCRIPTION, harness.command_line(SUITE, argv), tables,
        dict(parts=parts, settings=st, episode_seed=args.episode_seed, seed=args.seed,
             quick=args.quick, **out),
        time.perf_counter() - t0, machine=harness.machine_info(1 if st["fresh"] else None))
    harness.finish(args, record)
    return 0


if __name__ == "__main__":
    sys.exit(main())
