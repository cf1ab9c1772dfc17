"""Speed-up against the number of Numba threads: ``python -m benchmarks.bench_scaling``
(``seaice bench scaling``).

    python -m benchmarks.bench_scaling [--threads 1,2,4,...] [--workloads ceiling,hertz,vector,ppo]
                                 [--rounds 5] [--floes 20000] [--large-floes 200000]
                                 [--steps 2000] [--ceiling-floes 200000]
                                 [--ceiling-steps 1000] [--envs 64] [--vector-steps 20]
                                 [--ppo-steps 4096] [--seed 1] [--cache-dir .bench_cache]
                                 [--quiet] [--quick] [--json PATH | --no-json]

Each workload runs in a fresh process whose Numba pool has the most threads
asked for; in it, the thread counts take turns (``numba.set_num_threads``
before every timed segment), round after round.
"""
from __future__ import annotations

import statistics
import sys
import time
from collections.abc import Callable
from pathlib import Path

import numba
import numpy as np

from physics.hertz import usable_cores

from . import harness
from .harness import REPEATS

SUITE = "scaling"
TITLE = "Scaling with threads"
DESCRIPTION = """
Speed against the number of Numba threads (1, 2, 4, 8, … up to the whole
pool, `NUMBA_NUM_THREADS`, the top count included when it is not a power of
two), for the workloads that the engines and the environments run on many
cores, each beside a loop that shows what the machine itself gives:

* **ceiling**: a kick–drift-like `prange` pass over an (N × 8) float64 floe
  state array, N = 200000, one parallel region per step and nothing else: a
  memory-bound loop, the most that threads can give to the per-floe passes.
  Its speed-up is the reference line of every other workload;
* **Hertz step** (`HertzSimulation`, parallel kernels), in floe-steps/s over
  whole segments of steps, list rebuilds included: the loose Ā = 0.7 field of
  the Hertz suite with N = 20000 and N = 200000 floes, and its jammed Ā = 0.95
  packing with N = 20000 (the same prepared fields, kept in `--cache-dir`);
* **native vector environments** of ShipNavigation-v0 and ShipNavigation-v1
  with 64 sub-environments (`gymnasium.make_vec(...,
  vectorization_mode="vector_entry_point")`), stepped with seeded random
  actions from a reset until every sub-environment has ended an episode
  (whole transits: early steps, before the ship reaches the ice, cost far
  less than late ones among the floes it has set moving), episodes reset as
  they end: env steps/s = 64 × vector steps / s, at most three rounds;
  after the rounds, one more segment on one thread times the share of the
  step that runs outside the compiled calls that are parallel over the
  sub-environments, and so bounds their speed-up (Amdahl);
* **PPO training** (Stable-Baselines3, MLP policy, rollouts of 2048 steps over
  the sub-environments, minibatches of 128, 10 epochs) on the native vector
  environment of ShipNavigation-v0 with 64 sub-environments: training steps/s
  end to end, rollouts and updates together. Only Numba's threads change:
  PyTorch runs on one thread throughout, as `seaice train` runs it.

Each workload runs in a fresh process whose Numba pool has the most threads
asked for. In it every thread count gets its own copy of the workload (the
same seeded field, environments or model), made and warmed up before the
timing (compilation, kernel loading, a few steps, a first PPO rollout and
update); then the thread counts take turns, `numba.set_num_threads` before each
timed segment, round after round (five by default; the tables give the
number), so that the ratios are measured side by side on a shared machine
whose speed drifts. A rate is the best segment of the
rounds; the speed-up over one thread is best over best, with the range of the
ratios of segments of the same round beside it. The engine runs on at most the
cores the process may use (`physics.hertz.threads_within_cores`): thread counts
above them are marked in the notes.
"""

#: the workloads, in the order of the tables and the figure
WORKLOADS = ("ceiling", "hertz-loose", "hertz-loose-large", "hertz-jammed", "vector-v0",
             "vector-v1", "ppo-v0")
#: names for several workloads at once (``--workloads hertz``)
GROUPS = {"hertz": ("hertz-loose", "hertz-loose-large", "hertz-jammed"),
          "vector": ("vector-v0", "vector-v1"), "ppo": ("ppo-v0",)}
#: the environment of each environment workload
ENV_IDS = {"vector-v0": "iceenvs/ShipNavigation-v0", "vector-v1": "iceenvs/ShipNavigation-v1",
           "ppo-v0": "iceenvs/ShipNavigation-v0"}
#: what each workload's rate counts
UNITS = {"ceiling": "floe-steps/s", "hertz": "floe-steps/s", "vector": "env steps/s",
         "ppo": "training steps/s"}
#: the full run's sizes
DEFAULTS = dict(rounds=REPEATS, floes=20000, large_floes=200000, steps=2000,
                ceiling_floes=200000, ceiling_steps=1000, envs=64, vector_steps=20,
                ppo_steps=4096, ppo_rollout=None, small=False, fresh=True)
#: sizes of ``--quick`` (threads 1 and 2, each environment in its small
#: instance, iceenvs.facts.EnvFacts.small, everything in this process)
QUICK = dict(rounds=2, floes=400, large_floes=800, steps=20, ceiling_floes=4000,
             ceiling_steps=20, envs=2, vector_steps=3, ppo_steps=64, ppo_rollout=64, small=True,
             fresh=False, threads=(1, 2))
#: Δt of the ceiling loop's kick and drift [s]
CEILING_DT = 1e-3
#: untimed vector steps of every copy of a vector environment before the timing
VECTOR_WARMUP = 3
#: the most rounds of a vector workload (each round is a whole transit of
#: every sub-environment on every thread count)
VECTOR_ROUNDS = 3


def group(key: str) -> str:
    """The kind of a workload: ``ceiling``, ``hertz``, ``vector`` or ``ppo``."""
    return key.split("-")[0]


def default_threads(top: int) -> list[int]:
    """1, 2, 4, … below ``top``, and ``top``."""
    out, k = [], 1
    while k < top:
        out.append(k)
        k *= 2
    return out + [int(top)]


def parse_threads(text: str) -> list[int]:
    """The thread counts of ``--threads`` (``"1,2,4"``), sorted, with 1
    added: the speed-ups are over one thread.

    Raises
    ------
    ValueError
        If a count is not a whole number of at least 1, or none is given.
    """
    try:
        threads = [int(t) for t in str(text).split(",") if t.strip()]
    except ValueError:
        raise ValueError(f"--threads takes whole numbers separated by commas, got "
                         f"{text!r}") from None
    if not threads or min(threads) < 1:
        raise ValueError(f"--threads must name thread counts of at least 1, got {text!r}")
    return sorted(set(threads) | {1})


def parse_workloads(text: str | None) -> list[str]:
    """The workloads of ``--workloads`` (``"ceiling,hertz-jammed,ppo"``: names
    of :data:`WORKLOADS` or groups of :data:`GROUPS`) in the order of
    :data:`WORKLOADS`; ``None``: all of them.

    Raises
    ------
    ValueError
        If a name is unknown, or none is given.
    """
    return harness.pick_names(text, WORKLOADS, "workload", GROUPS)


# ---------------------------------------------------------------------------
# the workloads, each timed in one process
# ---------------------------------------------------------------------------

@numba.njit(parallel=True, cache=False)
def _ceiling_loop(state, steps, dt):
    """``steps`` kick–drift-like passes over an (N, 8) floe-state array, each
    pass one parallel region over the rows: the velocities kicked by the
    accelerations, the positions drifted, the squared speed stored."""
    n = state.shape[0]
    for _ in range(steps):
        for i in numba.prange(n):
            state[i, 2] += dt * state[i, 4]
            state[i, 3] += dt * state[i, 5]
            state[i, 0] += dt * state[i, 2]
            state[i, 1] += dt * state[i, 3]
            state[i, 6] = state[i, 2] * state[i, 2] + state[i, 3] * state[i, 3]
    return state[0, 6]


def _ceiling_runs(spec: dict, threads: list[int]) -> tuple[list, dict]:
    """One seeded (N, 8) array per thread count, the loop compiled and run
    once on each; the timed segments: ``steps`` passes."""
    n, steps = spec["n"], spec["steps"]
    base = np.random.default_rng(spec["seed"]).random((n, 8))
    states = [base.copy() for _ in threads]
    for k, state in zip(threads, states):
        numba.set_num_threads(k)
        _ceiling_loop(state, 1, CEILING_DT)

    def segment(k, state):
        def go():
            numba.set_num_threads(k)
            t0 = time.perf_counter()
            _ceiling_loop(state, steps, CEILING_DT)
            return n * steps / (time.perf_counter() - t0)
        return go

    return [segment(k, s) for k, s in zip(threads, states)], dict(steps=steps)


def _hertz_runs(spec: dict, threads: list[int]) -> tuple[list, dict, Callable]:
    """A warmed-up parallel simulation of the saved field per thread count
    (:func:`benchmarks.bench_hertz.warm_sim`); the timed segments: ``steps``
    steps. Also returns a function that gives the contacts per floe and the
    list rebuilds per segment after the timing."""
    from .bench_hertz import segment_rate, warm_sim

    sims = []
    for k in threads:
        numba.set_num_threads(k)
        sims.append(warm_sim(spec["path"], spec["dt"], parallel=True))
    rebuilds0 = sims[0].n_rebuilds

    def segment(k, sim):
        def go():
            numba.set_num_threads(k)
            return segment_rate(sim, spec["steps"])
        return go

    def after(rounds):
        return dict(contacts_per_floe=2.0 * len(sims[0].contacts()) / sims[0].n_floes,
                    rebuilds=(sims[0].n_rebuilds - rebuilds0) / rounds)

    return ([segment(k, s) for k, s in zip(threads, sims)],
            dict(steps=spec["steps"], dt=spec["dt"]), after)


def _vector_runs(spec: dict, threads: list[int]) -> tuple[list, dict, Callable]:
    """A native vector environment of ``n`` sub-environments per thread
    count, warmed up by a few steps; the timed segments: whole transits,
    each from a reset with the same seed and actions from a generator of the
    same seed, until every sub-environment has ended an episode (so that the
    steps weigh every part of an episode as training does: a ship costs
    little before it reaches the ice and most among the floes it has set
    moving). Its rate: env steps (n per vector step) over the segment's
    wall time."""
    import gymnasium as gym

    import iceenvs  # noqa: F401  (registers the ids)

    from .bench_vector import random_actions

    n, steps = spec["n"], spec["steps"]
    copies = []
    for k in threads:
        numba.set_num_threads(k)
        env = gym.make_vec(spec["env_id"], num_envs=n, vectorization_mode="vector_entry_point",
                           **spec["kwargs"])
        env.reset(seed=spec["seed"])
        rng = np.random.default_rng(spec["seed"])
        for _ in range(VECTOR_WARMUP):
            env.step(random_actions(env.single_action_space, rng, n))
        copies.append((env, rng))

    def segment(k, env):
        def go():
            numba.set_num_threads(k)
            space = env.single_action_space
            rng = np.random.default_rng(spec["seed"])
            env.reset(seed=spec["seed"])
            ended = np.zeros(n, dtype=bool)
            count = 0
            t0 = time.perf_counter()
            while not ended.all():
                _, _, term, trunc, _ = env.step(random_actions(space, rng, n))
                ended |= np.asarray(term) | np.asarray(trunc)
                count += 1
            return n * count / (time.perf_counter() - t0)
        return go

    def after(rounds):
        numba.set_num_threads(1)
        share = serial_share(*copies[0], n, steps)
        for env, _ in copies:
            env.close()
        return share

    return [segment(k, c[0]) for k, c in zip(threads, copies)], dict(steps=steps), after


#: the compiled calls of a native vector environment's step that run in
#: parallel over its sub-environments: (module, name)
PARALLEL_CALLS = (("physics.hertz", "run_many"), ("iceenvs.ship_measures", "measure_many"),
                  ("iceenvs.ship_measures", "ice_near_many"))


def serial_share(env, rng, n: int, steps: int) -> dict:
    """The share of a native vector environment's step (``env``, ``n``
    sub-environments, ``steps`` steps on one thread) spent outside the
    compiled calls that run in parallel over the sub-environments
    (:data:`PARALLEL_CALLS`): the Python that prepares, reads and ends the
    step one sub-environment after the other, and the resets. By Amdahl's
    law a step on p threads is at most 1 / (s + (1 − s) / p) times faster."""
    import importlib

    from .bench_vector import random_actions

    spent = [0.0]
    saved = []
    for module, name in PARALLEL_CALLS:
        owner = importlib.import_module(module)
        fn = getattr(owner, name)
        saved.append((owner, name, fn))

        def timed(*args, _fn=fn):
            t0 = time.perf_counter()
            out = _fn(*args)
            spent[0] += time.perf_counter() - t0
            return out
        setattr(owner, name, timed)
    try:
        space = env.single_action_space
        t0 = time.perf_counter()
        for _ in range(steps):
            env.step(random_actions(space, rng, n))
        wall = time.perf_counter() - t0
    finally:
        for owner, name, fn in saved:
            setattr(owner, name, fn)
    return dict(serial_share=max(0.0, 1.0 - spent[0] / wall),
                serial_ms=1e3 * (wall - spent[0]) / (n * steps))


def _ppo_runs(spec: dict, threads: list[int]) -> tuple[list, dict, Callable]:
    """A PPO model on its own native vector environment per thread count,
    all seeded alike, after one untimed rollout and update (as
    :func:`benchmarks.bench_vector.measure_training` trains); the timed segments:
    ``learn`` of at least ``steps`` more training steps. PyTorch runs on one
    thread, as the training command sets it (its threads and Numba's would
    otherwise share the cores), so that only Numba's threads change."""
    import torch
    from stable_baselines3 import PPO

    from agents.envs import make_vec_env

    from .bench_vector import ROLLOUT

    n = spec["n"]
    n_steps = max((spec["rollout"] or ROLLOUT) // n, 8)
    models = []
    saved = torch.get_num_threads()
    torch.set_num_threads(1)
    try:
        for k in threads:
            numba.set_num_threads(k)
            venv = make_vec_env(spec["env_id"], n_envs=n, seed=spec["seed"],
                                env_kwargs=spec["kwargs"], vectorization="native")
            model = PPO("MlpPolicy", venv, n_steps=n_steps, batch_size=min(128, n_steps * n),
                        seed=spec["seed"], device="cpu")
            model.learn(n_steps * n)             # one untimed rollout and update
            models.append(model)
    except BaseException:
        torch.set_num_threads(saved)
        raise

    def segment(k, model):
        def go():
            numba.set_num_threads(k)
            before = model.num_timesteps
            t0 = time.perf_counter()
            model.learn(spec["steps"], reset_num_timesteps=False)
            return (model.num_timesteps - before) / (time.perf_counter() - t0)
        return go

    def after(rounds):
        for model in models:
            model.get_env().close()
        torch.set_num_threads(saved)
        return {}

    info = dict(steps=spec["steps"], rollout=n_steps * n, torch_threads=torch.get_num_threads())
    return [segment(k, m) for k, m in zip(threads, models)], info, after


def time_workload(key: str, spec: dict, threads: list[int], rounds: int) -> dict:
    """Time workload ``key`` (prepared as ``spec`` says) on every thread
    count of ``threads`` in this process: a copy per thread count, warmed up,
    then ``rounds`` rounds of one timed segment per thread count, taking
    turns (:func:`benchmarks.harness.interleaved_rounds`). Returns the
    rates of every segment (``rates[j][r]``: thread count ``j``, round
    ``r``) and what the workload reports of itself."""
    threads = [int(k) for k in threads]
    saved = numba.get_num_threads()
    try:
        kind = group(key)
        if kind == "ceiling":
            runs, info = _ceiling_runs(spec, threads)
            after = None
        elif kind == "hertz":
            runs, info, after = _hertz_runs(spec, threads)
        elif kind == "vector":
            runs, info, after = _vector_runs(spec, threads)
        elif kind == "ppo":
            runs, info, after = _ppo_runs(spec, threads)
        else:
            raise ValueError(f"unknown workload {key!r}")
        rounds = min(rounds, spec.get("most_rounds", rounds))
        try:
            rates = harness.interleaved_rounds(runs, rounds)
        finally:
            extra = after(rounds) if after is not None else {}
        info.update(extra)
    finally:
        numba.set_num_threads(saved)
    return dict(rates=rates, pool=numba.config.NUMBA_NUM_THREADS, **info)


# ---------------------------------------------------------------------------
# the run
# ---------------------------------------------------------------------------

def workload_specs(keys, st: dict, seed: int, cache_dir: Path, quiet: bool) -> dict:
    """What each workload of ``keys`` times, with the floe fields prepared
    (and saved in ``cache_dir``) before any timing: key → dict(label, n,
    unit, and what :func:`time_workload` needs)."""
    from physics.params import HERMAN2013

    from .bench_hertz import loose_state, prepared_cases

    specs = {}
    for key in keys:
        kind = group(key)
        spec = dict(seed=seed, unit=UNITS[kind])
        if kind == "ceiling":
            spec.update(n=st["ceiling_floes"], steps=st["ceiling_steps"],
                        label=f"ceiling: kick–drift loop over N × 8 floats, N = "
                              f"{st['ceiling_floes']}")
        elif key in ("hertz-loose", "hertz-loose-large"):
            n = st["floes"] if key == "hertz-loose" else st["large_floes"]
            spec.update(n=n, steps=st["steps"], dt=HERMAN2013.time_step,
                        path=str(loose_state(n, seed, cache_dir)),
                        label=f"Hertz step, Ā = 0.70, N = {n}")
        elif key == "hertz-jammed":
            if not quiet:
                print(f"jammed field (N = {st['floes']}) ...", flush=True)
            name, path, dt = prepared_cases(st["floes"], seed, cache_dir, quiet)[1]
            spec.update(n=st["floes"], steps=st["steps"], dt=dt, path=str(path),
                        label=f"Hertz step, {name}, N = {st['floes']}")
        else:
            from iceenvs.facts import env_facts

            env_id = ENV_IDS[key]
            steps = st["vector_steps"] if kind == "vector" else st["ppo_steps"]
            what = "PPO on " if kind == "ppo" else ""
            if kind == "vector":
                spec.update(most_rounds=VECTOR_ROUNDS)
            spec.update(n=st["envs"], steps=steps, env_id=env_id, rollout=st["ppo_rollout"],
                        kwargs=dict(env_facts(env_id).small) if st["small"] else {},
                        label=f"{what}{env_id.split('/')[1]}, native vector env, "
                              f"N = {st['envs']}")
        specs[key] = spec
    return specs


def summarise(key: str, spec: dict, threads: list[int], out: dict) -> dict:
    """A workload's result: per thread count the best rate, the range of the
    rounds, the speed-up best over best and the same-round ratios over one
    thread (the first count)."""
    rates = out["rates"]
    one = rates[0]
    rows = []
    for k, r in zip(threads, rates):
        paired = [a / b for a, b in zip(r, one)]
        rows.append(dict(threads=k, rate=max(r), spread=[min(r), max(r)], rates=list(r),
                         speedup=max(r) / max(one), paired=paired,
                         paired_median=statistics.median(paired)))
    extra = {k: v for k, v in out.items() if k != "rates"}
    return dict(workload=key, label=spec["label"], unit=spec["unit"], n=spec["n"], rows=rows,
                **extra)


def run_benchmark(keys, threads: list[int], st: dict, seed: int, cache_dir: Path,
                  quiet: bool = False) -> list[dict]:
    """Every workload of ``keys`` on every thread count of ``threads`` (the
    first one is 1), each in a fresh process (``st["fresh"]``; else in this
    one); one result each (:func:`summarise`), or ``dict(failed=...)``."""
    specs = workload_specs(keys, st, seed, cache_dir, quiet)
    results = []
    with harness.Progress(len(keys), "scaling", quiet, unit="workload") as bar:
        for key in keys:
            spec = specs[key]
            try:
                if st["fresh"]:
                    out = harness.spawn_call(time_workload, key, spec, threads, st["rounds"],
                                             threads=max(threads))
                else:
                    out = time_workload(key, spec, threads, st["rounds"])
            except harness.ChildError as exc:
                tail = (str(exc).strip().splitlines() or ["(no output)"])[-1]
                results.append(dict(workload=key, label=spec["label"], unit=spec["unit"],
                                    n=spec["n"], failed=tail))
                bar.log(f"  {spec['label']}: failed: {tail}")
                bar.advance()
                continue
            result = summarise(key, spec, threads, out)
            results.append(result)
            bar.log(f"  {spec['label']}: " + ", ".join(
                f"{r['threads']}: {r['rate']:.3g} ({r['speedup']:.2f}x)" for r in result["rows"])
                + f" {spec['unit']}")
            bar.advance()
    return results


# ---------------------------------------------------------------------------
# the record
# ---------------------------------------------------------------------------

def _thread_columns(threads) -> list[str]:
    return [f"{k} thread{'s' * (k != 1)}" for k in threads]


def rates_table(results: list[dict], threads: list[int], rounds: int) -> dict:
    """Rates: a row per workload, a column per thread count (the best
    segment, and how much slower the slowest round was)."""
    body = []
    for res in results:
        if "failed" in res:
            body.append([res["label"], res["unit"]] + [f"failed: {res['failed']}"]
                        + [""] * (len(threads) - 1))
            continue
        cells = []
        for r in res["rows"]:
            lo, hi = r["spread"]
            cells.append(f"{harness.format_number(hi)} (−{100 * (1 - lo / hi):.0f} %)")
        body.append([res["label"], res["unit"]] + cells)
    notes = ["Each cell: the best segment, and in brackets how much slower the slowest round "
             "of the same thread count was."]
    if any(group(res["workload"]) == "vector" for res in results):
        notes.append(f"An environment's steps cost more as its episodes go on: the ship sets "
                     f"moving the floes it pushes, and a floe that drifts free costs little. "
                     f"A vector environment's segment is therefore a whole transit of every "
                     f"sub-environment from the same reset (at most {VECTOR_ROUNDS} rounds), "
                     f"so that the thread counts of one round compare like with like and the "
                     f"rate is the one training sustains.")
    return harness.table(
        f"Rate against Numba threads (best of {rounds} rounds)",
        ["workload", "unit"] + _thread_columns(threads), body, "\n\n".join(notes))


def speedup_table(results: list[dict], threads: list[int], rounds: int, cores: int) -> dict:
    """Speed-ups over one thread: a row per workload (the ceiling loop
    first, the reference), a column per thread count."""
    body = []
    for res in results:
        if "failed" in res:
            continue
        cells = []
        for r in res["rows"]:
            if r["threads"] == 1:
                cells.append(f"{r['speedup']:.2f}")
            else:
                cells.append(f"{r['speedup']:.2f} ({min(r['paired']):.2f}–"
                             f"{max(r['paired']):.2f})")
        body.append([res["label"]] + cells)
    notes = [f"Best rate over best rate on one thread; in brackets the range of the ratios of "
             f"the {rounds} rounds (two segments of the same round). The ceiling loop's row is "
             f"the reference: a workload that scales as well as it does is limited by the "
             f"machine, not by its own code."]
    over = [k for k in threads if k > cores]
    if over:
        notes.append(f"The process may use {cores} cores: on {', '.join(map(str, over))} "
                     f"threads the Hertz step and the vector environments run on {cores} "
                     f"threads (physics.hertz.threads_within_cores); the ceiling loop runs on "
                     f"all it is given.")
    torch_threads = {res.get("torch_threads") for res in results if res.get("torch_threads")}
    if torch_threads:
        count = ", ".join(map(str, sorted(torch_threads)))
        notes.append(f"PPO: PyTorch on {count} thread{'s' * (count != '1')} throughout; "
                     f"only Numba's threads change.")
    hertz = [res for res in results if "contacts_per_floe" in res]
    if hertz:
        notes.append("Hertz cases: " + "; ".join(
            f"{res['label']}: {harness.format_number(res['contacts_per_floe'])} contacts per "
            f"floe, {res['rebuilds']:.1f} list rebuilds per segment of {res['steps']} steps"
            for res in hertz))
    return harness.table("Speed-up over one thread", ["workload"] + _thread_columns(threads),
                         body, "\n\n".join(notes))


def serial_table(results: list[dict]) -> dict | None:
    """The serial share of each native vector environment's step and the
    speed-ups it allows (Amdahl), or None without them."""
    rows = []
    for res in results:
        if "serial_share" not in res:
            continue
        s = res["serial_share"]
        rows.append([res["label"], f"{100 * s:.1f} %", f"{res['serial_ms'] * 1e3:.0f}",
                     f"{1 / (s + (1 - s) / 16):.1f}", f"{1 / (s + (1 - s) / 64):.1f}"])
    if not rows:
        return None
    return harness.table(
        "Native vector environments: the part of a step that runs one sub-environment "
        "after the other (one thread)",
        ["workload", "serial share s", "µs per env step", "most speed-up on 16 threads",
         "on 64 threads"], rows,
        "The serial share is the step's time outside the compiled calls that run in parallel "
        "over the sub-environments (the engines' run_many, the step records and lidar of "
        "measure_many and the local ice of ice_near_many): the Python that applies the "
        "actions, prepares and reads the engines, measures, scores, observes, builds the "
        "info and resets the episodes that end, one sub-environment after the other. By "
        "Amdahl's law p threads make a step at most 1 / (s + (1 − s) / p) times faster, "
        "before the memory-bound ceiling takes its share.")


def main(argv=None, prog: str | None = None) -> int:
    p = harness.suite_parser(SUITE, TITLE + ": " + DESCRIPTION, prog)
    p.add_argument("--threads", default=None,
                   help="thread counts, comma-separated, e.g. 1,2,4 (default 1, 2, 4, … up to "
                        "NUMBA_NUM_THREADS; 1 is always timed)")
    p.add_argument("--workloads", default=None,
                   help="workloads, comma-separated: " + ", ".join(WORKLOADS) + ", or the groups "
                        + ", ".join(GROUPS) + " (default: all)")
    p.add_argument("--rounds", type=int, default=None,
                   help=f"rounds of turns (default {DEFAULTS['rounds']})")
    p.add_argument("--floes", type=int, default=None,
                   help="floes of the Hertz cases at Ā = 0.7 and jammed (default 20000)")
    p.add_argument("--large-floes", type=int, default=None,
                   help="floes of the large Hertz case at Ā = 0.7 (default 200000)")
    p.add_argument("--steps", type=int, default=None,
                   help="Hertz steps per timed segment (default 2000)")
    p.add_argument("--ceiling-floes", type=int, default=None,
                   help="rows of the ceiling loop's state array (default 200000)")
    p.add_argument("--ceiling-steps", type=int, default=None,
                   help="passes of the ceiling loop per timed segment (default 1000)")
    p.add_argument("--envs", type=int, default=None,
                   help="sub-environments of the vector environments and PPO (default 64)")
    p.add_argument("--vector-steps", type=int, default=None,
                   help="vector steps per timed segment (default 20)")
    p.add_argument("--ppo-steps", type=int, default=None,
                   help="PPO training steps per timed segment (default 4096)")
    p.add_argument("--seed", type=int, default=1,
                   help="seed of the floe fields, the ceiling's array, the episodes, actions "
                        "and PPO")
    p.add_argument("--cache-dir", type=Path, default=harness.CACHE_DIR,
                   help=f"where the prepared floe fields are kept "
                        f"(default {harness.in_checkout(harness.CACHE_DIR)})")
    args, argv = harness.parse(p, argv)
    st = harness.settings(args, DEFAULTS, QUICK, ("rounds", "floes", "large_floes", "steps",
                                                  "ceiling_floes", "ceiling_steps", "envs",
                                                  "vector_steps", "ppo_steps"))
    if min(st[k] for k in ("rounds", "steps", "ceiling_steps", "envs", "vector_steps",
                           "ppo_steps")) < 1:
        p.error("--rounds, --steps, --ceiling-steps, --envs, --vector-steps and --ppo-steps "
                "must be at least 1")
    if min(st["floes"], st["large_floes"], st["ceiling_floes"]) < 100:
        p.error("--floes, --large-floes and --ceiling-floes must be at least 100")

    pool = numba.config.NUMBA_NUM_THREADS
    try:
        if args.threads is not None:
            threads = parse_threads(args.threads)
        else:
            threads = parse_threads(",".join(
                str(k) for k in (st["threads"] if args.quick else default_threads(pool))
                if k <= pool))
        keys = parse_workloads(args.workloads)
    except ValueError as exc:
        p.error(str(exc))
    if not st["fresh"] and max(threads) > pool:
        p.error(f"--quick runs in this process, whose Numba pool has {pool} threads: "
                f"--threads must not exceed it")

    t0 = time.perf_counter()
    results = run_benchmark(keys, threads, st, args.seed, args.cache_dir, args.quiet)
    cores = usable_cores()
    tables = [rates_table(results, threads, st["rounds"]),
              speedup_table(results, threads, st["rounds"], cores)]
    serial = serial_table(results)
    if serial is not None:
        tables.append(serial)
    settings = {k: v for k, v in st.items() if k != "threads"}
    record = harness.make_record(
        SUITE, TITLE, DESCRIPTION, harness.command_line(SUITE, argv), tables,
        dict(threads=threads, workloads=keys, settings=settings, seed=args.seed,
             usable_cores=cores, quick=args.quick, results=results),
        time.perf_counter() - t0,
        machine=harness.machine_info(max(threads) if st["fresh"] else pool))
    harness.finish(args, record)
    return 1 if any("failed" in r for r in results) else 0


if __name__ == "__main__":
    sys.exit(main())
