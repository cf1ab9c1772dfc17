"""Vectorised stepping and training side by side: ``python -m benchmarks.bench_vector``
(``seaice bench vector``).

    python -m benchmarks.bench_vector [--ids ShipNavigation-v0 ...] [--sizes 1 8 16 32]
                                [--seconds 5] [--rounds 3] [--ppo-envs 16]
                                [--ppo-steps 8192] [--no-ppo] [--quick]
                                [--json PATH | --no-json]
"""
from __future__ import annotations

import math
import statistics
import sys
import time

from . import harness

SUITE = "vector"
TITLE = "Vector environments"
DESCRIPTION = """
Environment steps per second of an environment stepped four ways, for N
sub-environments: the single environment (one process, Numba on one
thread), Gymnasium's `SyncVectorEnv` (one process, one after the other,
Numba on one thread), Stable-Baselines3's `SubprocVecEnv` (a worker process
per sub-environment) and the environment's native vector environment
(`gymnasium.make_vec(..., vectorization_mode="vector_entry_point")`: one
process, the engines of all sub-environments advanced in one compiled call,
Numba on all the machine's threads). Each measurement runs in a fresh
process: seeded random actions, a warm-up (the kernels loaded and a second of
untimed steps), then, from a reset, timed steps until every sub-environment
has ended an episode and at least the stated wall seconds have passed, the
episodes reset as they end: whole episodes, so that every part of one
weighs as it does in training (a ship's transit costs little before the
ship reaches the ice and most where it has set the pack moving). The configurations take turns, round after
round, so that the load of a shared machine falls on all of them alike; the
tables give the mean over the rounds and their range.

The last table times end-to-end training: Stable-Baselines3 PPO (MLP
policy, rollouts of 2048 steps over the sub-environments, minibatches of
128, 10 epochs) through `agents.envs.make_vec_env` with each
vectorization, after one untimed rollout and update: the training steps
per second that a run sees.
"""
#: the environments timed by default (default configurations)
DEFAULT_IDS = ("iceenvs/ShipNavigation-v0", "iceenvs/ShipNavigation-v1", "iceenvs/ShipBeset-v0",
               "iceenvs/WindDrift-v0")
DEFAULT_SIZES = (1, 8, 16, 32)
#: settings of ``--quick``
#: (each environment in its small instance, iceenvs.facts.EnvFacts.small, in
#: this process instead of fresh ones, rollouts of 64 steps instead of
#: ROLLOUT, and no PPO run over worker processes)
QUICK = dict(seconds=0.3, rounds=1, sizes=(2,), ppo_envs=2, ppo_steps=64, ppo_rollout=64,
             small=True, fresh=False)
MODES = ("single", "sync", "subproc", "native")
#: the sub-environments and steps of a PPO rollout
ROLLOUT = 2048


def random_actions(space, rng, n):
    """``n`` actions drawn uniformly from the box ``space`` with ``rng``."""
    return rng.uniform(space.low, space.high, (n,) + space.shape).astype(space.dtype)


def _warm_up(step, seconds: float):
    """One ``step()`` (the kernels loaded, however long that takes), then
    ``step()`` for up to a second more, before a timing starts."""
    step()
    t0 = time.perf_counter()
    while time.perf_counter() - t0 < min(1.0, seconds):
        step()


def measure_stepping(mode: str, env_id: str, n: int, seconds: float, seed: int,
                     kwargs: dict | None = None) -> dict:
    """Env steps/s of ``env_id`` stepped ``mode``-wise with ``n``
    sub-environments ("single" ignores ``n``), in this process: after a
    warm-up, from a reset until every sub-environment has ended an episode
    and at least ``seconds`` have passed (whole episodes, each as
    training sees it)."""
    import gymnasium as gym
    import numpy as np

    import iceenvs  # noqa: F401

    kwargs = dict(kwargs or {})
    rng = np.random.default_rng(seed)
    if mode == "single":
        env = gym.make(env_id, **kwargs)
        space = env.action_space
        n = 1

        def reset():
            env.reset(seed=seed)

        def step():
            _, _, term, trunc, _ = env.step(random_actions(space, rng, 1)[0])
            if term or trunc:
                env.reset()
            return np.array([term or trunc])
    elif mode == "subproc":
        from stable_baselines3.common.vec_env import SubprocVecEnv

        from agents.envs import EnvFactory

        env = SubprocVecEnv([EnvFactory(env_id, kwargs, seed + k) for k in range(n)])
        space = env.action_space

        def reset():
            env.seed(seed)
            env.reset()

        def step():
            return np.asarray(env.step(random_actions(space, rng, n))[2], dtype=bool)
    else:
        if mode == "native":
            env = gym.make_vec(env_id, num_envs=n, vectorization_mode="vector_entry_point",
                               **kwargs)
        else:
            env = gym.vector.SyncVectorEnv([lambda: gym.make(env_id, **kwargs)] * n)
        space = env.single_action_space

        def reset():
            env.reset(seed=seed)

        def step():
            _, _, term, trunc, _ = env.step(random_actions(space, rng, n))
            return np.asarray(term) | np.asarray(trunc)
    reset()
    _warm_up(step, seconds)
    reset()
    ended = np.zeros(n, dtype=bool)
    steps = episodes = 0
    t0 = time.perf_counter()
    while True:
        done = step()
        steps += n
        episodes += int(done.sum())
        ended |= done
        wall = time.perf_counter() - t0
        if wall >= seconds and ended.all():
            break
    env.close()
    return dict(mode=mode, id=env_id, n=n, steps=steps, seconds=wall, rate=steps / wall,
                episodes=episodes)


def measure_training(mode: str, env_id: str, n: int, steps: int, seed: int,
                     kwargs: dict | None = None, rollout: int = ROLLOUT) -> dict:
    """End-to-end PPO training steps/s with ``n`` sub-environments stepped
    ``mode``-wise (``agents.envs.make_vec_env``), in this process, with
    rollouts of ``rollout`` steps over the sub-environments."""
    from stable_baselines3 import PPO

    from agents.envs import make_vec_env

    venv = make_vec_env(env_id, n_envs=n, seed=seed, env_kwargs=kwargs,
                        vectorization={"sync": "dummy"}.get(mode, mode))
    n_steps = max(rollout // n, 8)
    model = PPO("MlpPolicy", venv, n_steps=n_steps, batch_size=min(128, n_steps * n),
                seed=seed, device="cpu")
    model.learn(n_steps * n)                 # one untimed rollout and update
    t0 = time.perf_counter()
    model.learn(steps, reset_num_timesteps=False)
    wall = time.perf_counter() - t0
    done = model.num_timesteps - n_steps * n
    venv.close()
    return dict(mode=mode, id=env_id, n=n, steps=done, seconds=wall, rate=done / wall)


def measure_phases(env_id: str, seconds: float, seed: int, n: int,
                   kwargs: dict | None = None) -> dict:
    """Where a step's time goes, in this process: per env step, the engine
    (``sim.advance``; the native vector environment's ``advance_together``
    over its ``n`` sub-environments) and the rest of the environment's own
    ``step`` (action, measurements, observation, reward, info, resets), for
    the single environment on one thread and the native vector environment;
    and the engine's time per engine sub-step in the environment's field and
    in a nearly empty one (the fixed cost of a sub-step: the ship's and the
    loop's). The steps are the environments' real ones, random actions; the
    engine calls are timed from inside them (:class:`_EngineClock`)."""
    import gymnasium as gym
    import numpy as np

    import iceenvs  # noqa: F401
    from iceenvs.ship_env import ShipEnv

    rng = np.random.default_rng(seed)
    out = {}

    def timed(env, per_env: int):
        """Per env step: engine and rest [ms], engine per sub-step [ns], mean
        floes and awake floes, over ``seconds`` of ``env.step``."""
        def step():
            _, _, terminated, truncated, _ = env.step(rng.uniform(-1, 1, env.action_space.shape))
            if per_env == 1 and (terminated or truncated):
                env.reset()

        _warm_up(step, seconds)
        with _EngineClock() as clock:
            count = 0
            t0 = time.perf_counter()
            while time.perf_counter() - t0 < seconds:
                step()
                count += 1
            total = time.perf_counter() - t0
        steps = count * per_env
        return dict(engine_ms=1e3 * clock.seconds / steps,
                    rest_ms=1e3 * (total - clock.seconds) / steps,
                    substep_ns=1e9 * clock.seconds / clock.substeps,
                    floes=clock.floes / clock.sims, awake=clock.awake / clock.sims)

    env = gym.make(env_id, **(kwargs or {}))
    env.reset(seed=seed)
    out["single"] = timed(env, 1)
    if isinstance(env.unwrapped, ShipEnv):
        empty = gym.make(env_id, **{**(kwargs or {}), "concentration": 0.05})
        empty.reset(seed=seed)
        out["empty"] = timed(empty, 1)
    envs = gym.make_vec(env_id, num_envs=n, vectorization_mode="vector_entry_point",
                        **(kwargs or {}))
    envs.reset(seed=seed)
    out["native"] = timed(envs, n)
    envs.close()
    return dict(id=env_id, n=n, **out)


class _EngineClock:
    """Within its ``with`` block, times every engine call of the
    environments (``HertzSimulation.advance`` and the native vector
    environment's ``advance_together``) and counts their sub-steps and
    floes; the calls themselves are unchanged."""

    def __enter__(self):
        import iceenvs.step
        from physics.hertz import HertzSimulation

        self.seconds = 0.0
        self.substeps = self.sims = self.floes = self.awake = 0
        self._saved = [(HertzSimulation, "advance", HertzSimulation.advance),
                       (iceenvs.step, "advance_together", iceenvs.step.advance_together)]
        advance, together = (saved[2] for saved in self._saved)

        inside = [False]            # advance_together of one simulation calls its advance

        def timed_advance(sim, duration):
            if inside[0]:
                return advance(sim, duration)
            t0 = time.perf_counter()
            advance(sim, duration)
            self.seconds += time.perf_counter() - t0
            self._count([sim], duration)

        def timed_together(sims, duration, **kwargs):
            inside[0] = True
            t0 = time.perf_counter()
            try:
                errors = together(sims, duration, **kwargs)
            finally:
                inside[0] = False
            self.seconds += time.perf_counter() - t0
            self._count(sims, duration)
            return errors

        HertzSimulation.advance = timed_advance
        iceenvs.step.advance_together = timed_together
        return self

    def _count(self, sims, duration):
        for sim in sims:
            self.substeps += round(duration / sim.dt)
            self.sims += 1
            self.floes += sim.n_floes
            self.awake += sim.n_awake

    def __exit__(self, *exc):
        for owner, name, value in self._saved:
            setattr(owner, name, value)
        return False


def lambda_phases(mode: str, *args) -> dict:
    """:func:`measure_phases` called as :func:`_child` calls (``mode`` only
    chooses the threads: all of them, for the native vector environment)."""
    return measure_phases(*args)


def _child(fn, mode, *args, fresh: bool = True) -> dict:
    """``fn`` in a fresh process (``fresh``; else in this one): Numba on all
    threads for the native vector environment, on one thread otherwise."""
    threads = None if mode == "native" else 1
    try:
        if not fresh:
            return fn(mode, *args)
        return harness.spawn_call(fn, mode, *args, threads=threads, daemon=mode != "subproc")
    except (harness.ChildError, RuntimeError) as exc:
        tail = (str(exc).strip().splitlines() or ["(no output)"])[-1]
        return dict(mode=mode, failed=tail)


def _summary(runs: list[dict]) -> dict:
    failed = [r["failed"] for r in runs if "failed" in r]
    if failed:
        return dict(failed=failed[0])
    rates = [r["rate"] for r in runs]
    out = dict(rates=rates, mean=statistics.fmean(rates), min=min(rates), max=max(rates))
    if all("episodes" in r for r in runs):
        out["episodes"] = [r["episodes"] for r in runs]
    return out


def run_benchmark(ids, sizes, seconds: float, rounds: int, seed: int, ppo_envs: int | None,
                  ppo_steps: int, small: bool = False, fresh: bool = True,
                  quiet: bool = False, ppo_rollout: int = ROLLOUT) -> dict:
    """Every configuration, in turns, ``rounds`` times; then the training runs.
    ``small``: each environment in its small instance instead of its default;
    ``fresh``: each measurement in a fresh process (else all in this one,
    without PPO over worker processes); ``ppo_rollout``: the steps of a PPO
    rollout over the sub-environments."""
    from iceenvs.facts import env_facts

    kwargs = {i: dict(env_facts(i).small) if small else {} for i in ids}
    cases = []
    for env_id in ids:
        cases.append(("single", env_id, 1))
        cases += [(mode, env_id, n) for n in sizes for mode in MODES[1:]]
    train = [] if ppo_envs is None else [(mode, ids[0], ppo_envs) for mode in MODES[1:]
                                         if fresh or mode != "subproc"]
    runs: dict = {c: [] for c in cases}
    trained: dict = {c: [] for c in train}
    with harness.Progress(rounds * (len(cases) + len(train)), "vector", quiet) as bar:
        for r in range(rounds):
            for case in cases:
                runs[case].append(_child(measure_stepping, *case, seconds, seed + r,
                                         kwargs[case[1]], fresh=fresh))
                bar.advance()
            for case in train:
                trained[case].append(_child(measure_training, *case, ppo_steps, seed + r,
                                            kwargs[case[1]], ppo_rollout, fresh=fresh))
                bar.advance()
    with harness.Progress(1, "where the time goes", quiet) as bar:
        phases = _child(lambda_phases, "native", ids[0], seconds, seed, max(sizes), kwargs[ids[0]],
                        fresh=fresh)
        bar.advance()
    stepping = [dict(mode=m, id=i, n=n, **_summary(runs[(m, i, n)])) for m, i, n in cases]
    training = [dict(mode=m, id=i, n=n, **_summary(trained[(m, i, n)])) for m, i, n in train]
    return dict(settings=dict(ids=list(ids), sizes=list(sizes), seconds=seconds, rounds=rounds,
                              seed=seed, ppo_envs=ppo_envs, ppo_steps=ppo_steps,
                              ppo_rollout=ppo_rollout, small=small, fresh=fresh),
                stepping=stepping, training=training, phases=phases)


def _rate(r: dict) -> str:
    if "failed" in r:
        return f"failed: {r['failed']}"
    return f"{r['mean']:.0f} ({r['min']:.0f}–{r['max']:.0f})"


def stepping_table(result: dict, env_id: str) -> dict:
    """Env steps/s of one environment: a row per N, a column per way."""
    rows_of = [r for r in result["stepping"] if r["id"] == env_id]
    single = next(r for r in rows_of if r["mode"] == "single")
    rows = []
    for n in result["settings"]["sizes"]:
        row = [n, _rate(single)]
        for mode in MODES[1:]:
            r = next(x for x in rows_of if x["mode"] == mode and x["n"] == n)
            row.append(_rate(r))
        native = next(x for x in rows_of if x["mode"] == "native" and x["n"] == n)
        ok = "failed" not in native and "failed" not in single
        row.append(f"{native['mean'] / single['mean']:.1f}" if ok else "")
        rows.append(row)
    return harness.table(
        f"{env_id}: environment steps per second (mean over the rounds, and their range)",
        ["N", "single (1 core)", "SyncVectorEnv (1 core)", "SubprocVecEnv", "native",
         "native / single"], rows,
        "The single environment does not depend on N; it is timed once per round.")


def phases_table(result: dict) -> dict:
    """Where the time of a step goes (:func:`measure_phases`)."""
    ph = result["phases"]
    if "failed" in ph:
        return harness.table("Where the time goes", ["what", "failed"], [["", ph["failed"]]])
    rows = []
    labels = (("single", "single environment, its field (one core)"),
              ("empty", "single environment, a sparse field (A = 0.05)"),
              ("native", f"native vector environment, N = {ph['n']}, per env step"))
    for key, label in labels:
        if key in ph:
            r = ph[key]
            rows.append([label, f"{r['engine_ms']:.3f}", f"{r['substep_ns']:.0f}",
                         f"{r['rest_ms']:.3f}", f"{r.get('floes', math.nan):.0f}",
                         f"{r.get('awake', math.nan):.0f}"])
    return harness.table(
        f"{ph['id']}: where the time of a step goes",
        ["case", "engine [ms/step]", "engine per sub-step [ns]",
         "the rest of the step [ms/step]", "floes", "awake floes"], rows,
        "The environments' own steps are timed, with their engine calls timed from inside "
        "them. The engine is the compiled step over the control interval (about 1500 "
        "sub-steps of Δt) with the Python that prepares and reads it; the rest is the action, "
        "the measurements, the observation, the reward, the info and the resets of ended "
        "episodes, in Python. The sparse field (a few floes) shows the fixed cost of a sub-step: the "
        "ship's kick–drift, its contact pass and step record, and the loop. Floes and awake "
        "floes are means over the timed steps (per sub-environment); a floe at rest costs "
        "nothing (skip_resting), an awake one its kick–drift and its pairs at every sub-step. "
        "In the native vector environment the engines of all sub-environments run in "
        "parallel and the rest one after the other.")


def training_table(result: dict) -> dict:
    rows = [[r["mode"].replace("sync", "dummy"), r["n"], _rate(r)] for r in result["training"]]
    st = result["settings"]
    return harness.table(
        f"{st['ids'][0]}: PPO training steps per second end to end ({st['ppo_steps']} "
        f"timed steps)", ["vectorization", "N", "training steps/s"], rows,
        "dummy: SB3's DummyVecEnv (one after the other in the training process).")


def main(argv=None, prog: str | None = None) -> int:
    from iceenvs import ENV_IDS
    from iceenvs.facts import env_creator

    from .bench_environments import resolve_ids

    parser = harness.suite_parser(SUITE, TITLE + ": " + DESCRIPTION, prog)
    parser.add_argument("--ids", nargs="+", metavar="ID",
                        help="environments with a native vector environment (default: "
                             + ", ".join(i.split("/")[1] for i in DEFAULT_IDS) + ")")
    parser.add_argument("--sizes", nargs="+", type=int, metavar="N",
                        help="numbers of sub-environments (default 1 8 16 32)")
    parser.add_argument("--seconds", type=float, default=None,
                        help="minimum wall seconds of each timed run (default 5)")
    parser.add_argument("--rounds", type=int, default=None, help="rounds of turns (default 3)")
    parser.add_argument("--ppo-envs", type=int, default=None,
                        help="sub-environments of the PPO runs (default 16)")
    parser.add_argument("--ppo-steps", type=int, default=None,
                        help="timed PPO steps per run (default 8192)")
    parser.add_argument("--no-ppo", action="store_true", help="skip the PPO runs")
    parser.add_argument("--seed", type=int, default=0, help="seed of the episodes and actions")
    args, argv = harness.parse(parser, argv)
    st = harness.settings(args, dict(seconds=5.0, rounds=3, sizes=DEFAULT_SIZES, ppo_envs=16,
                                     ppo_steps=8192, ppo_rollout=ROLLOUT, small=False,
                                     fresh=True), QUICK,
                          ("seconds", "rounds", "sizes", "ppo_envs", "ppo_steps"))
    if st["seconds"] <= 0 or st["rounds"] < 1 or min(st["sizes"]) < 1 or st["ppo_envs"] < 1 \
            or st["ppo_steps"] < 1:
        parser.error("--seconds must be positive; --rounds, --sizes, --ppo-envs and "
                     "--ppo-steps at least 1")
    ids = resolve_ids(args.ids, ENV_IDS) if args.ids else list(DEFAULT_IDS)
    plain = [i for i in ids if not env_creator(i).engines_together]
    if plain:
        parser.error(f"{', '.join(plain)}: its native vector environment advances no engines "
                     f"together (this suite times the Hertz environments')")
    command = harness.command_line(SUITE, argv)
    t0 = time.perf_counter()
    result = run_benchmark(ids, st["sizes"], st["seconds"], st["rounds"], args.seed,
                           None if args.no_ppo else st["ppo_envs"], st["ppo_steps"],
                           st["small"], st["fresh"], args.quiet, st["ppo_rollout"])
    tables = [stepping_table(result, i) for i in ids] + [phases_table(result)]
    if result["training"]:
        tables.append(training_table(result))
    record = harness.make_record(SUITE, TITLE, DESCRIPTION, command, tables,
                                 dict(result, quick=args.quick), time.perf_counter() - t0)
    harness.finish(args, record)
    failed = any("failed" in r for r in result["stepping"] + result["training"])
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
