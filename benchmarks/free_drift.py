"""The free-drift step against the exact one: ``python -m benchmarks.free_drift``
(``seaice bench free_drift``).

    python -m benchmarks.free_drift [--parts statistics,speed] [--seeds 10]
                                    [--concentrations 0.2,0.3,0.4,0.5]
                                    [--policies straight,lattice] [--seed 10000]
                                    [--workers 2] [--speed-seed 10001] [--rounds 3]
                                    [--late-after 100]
                                    [--quiet] [--quick] [--json PATH | --no-json]

The episodes of the statistics are shared among ``--workers`` processes, each
on one Numba thread; the speed is measured in a fresh process of its own, on
one thread, before them.
"""
from __future__ import annotations

import concurrent.futures
import math
import multiprocessing
import os
import sys
import time

import numba
import numpy as np

from . import harness

SUITE = "free_drift"
TITLE = "Free drift: the fast serial step against the exact one"
DESCRIPTION = """
What the free-drift step (`HertzSimulation(free_drift=True)`, the ship
environments' `free_drift=True`) changes in the ship's episodes and what it
saves. The floes that provably cannot touch anything during a window of
steps drift in closed form, the others take the full contact step: the same
physics up to rounding. Granular contact dynamics are chaotic, so an episode
run with each step from the same seed follows the same trajectory for a
while and then another one; only the statistics over many fields can agree,
and they are what is compared here, against the exact step
(`free_drift=False`, the default, which skips the floes at rest).

* **Statistics.** `iceenvs/ShipNavigation-v1` at ice concentrations
  A = 0.2, 0.3, 0.4 and 0.5 (the environment's `concentration`, set as the
  leaderboard sets it), 10 fields each, field k seeded 10000 + k as the
  leaderboard seeds them, with two of the leaderboard's policies: the
  straight line (`straight`, whose action on this prescribed ship is zero
  throughout) and the lattice planner (`lattice`, `agents.planners`). Every
  field is sailed twice, with the exact and with the fast step, one after the
  other in the same worker process. From each episode's final info: the ice
  impulse per metre, the collisions, the energy given to the ice and the path
  length, and the episode's wall time (reset and policy included). For each
  concentration, policy and metric: the mean under each step, the
  difference of the means relative to the exact mean, and the standard error
  of the mean of the per-field (paired) differences. A row passes when the
  difference of the means is within 2 % of the exact mean *and* within two
  standard errors of the paired differences; the tables say which rows do
  not. Whether route choice pays is given for each step side by side: the
  lattice planner's mean impulse per metre over the straight line's.
* **The control.** The same fields sailed a third time with the exact step,
  every mobile floe's velocity nudged at reset by a normal variate of
  standard deviation 1e-12 m/s (seeded by the field): two exact runs a
  rounding error apart, compared by the same criteria. The fast step adds
  nothing but rounding (its check mode, which steps the free floes one
  step at a time, gives the exact step's episodes bit for bit; the tests
  check it), and the contacts amplify rounding until episodes from the same
  field part; the control shows how far apart that alone takes the means
  over this many fields.
* **Speed.** One straight-line episode (zero action) of ShipNavigation-v1,
  seed 10001, its concentration as the environment draws it, in a fresh
  process on one Numba thread: env steps/s over the whole episode (the
  steps' own wall time, the reset left out) and the mean wall time of an env
  step after env step 100, under each step. The two steps take turns, round
  after round (three rounds; each figure is the best round, with the slowest
  beside it), after one untimed episode of each that compiles and loads
  every kernel. Beside them the floes the step integrates: those awake (exact
  step) or engaged (fast step) at the end of each env step, on average, and
  for the fast step the engaged floe-steps over the steps of its tally
  (`sim.free_tally`), against the number of floes.

The episodes of the statistics run in two worker processes, each on one
Numba thread, each warmed up before its first episode by one untimed episode
of every policy under each step on the environment's small instance, so that
no compilation falls into an episode's wall time. Every random number is
seeded: the fields by their seeds, the policies by the first field's.
"""

#: the environment whose episodes are compared
ENV_ID = "iceenvs/ShipNavigation-v1"
#: the parts of the suite
PARTS = ("statistics", "speed")
#: the policies compared by default, as the leaderboard names them
POLICIES = ("straight", "lattice")
#: the metrics of each episode's final info: (key, label, scale, unit)
METRICS = (("impulse_per_metre", "impulse per metre", 1e3, "kN s/m"),
           ("collisions", "collisions", 1.0, ""),
           ("energy_to_ice", "energy to the ice", 1e6, "MJ"),
           ("path_length", "path length", 1.0, "m"))
#: a row passes when the difference of the means is within this fraction of
#: the exact mean ...
RELATIVE_TOLERANCE = 0.02
#: ... and within this many standard errors of the paired differences
STANDARD_ERRORS = 2.0
#: the two steps, by their ``free_drift`` flag
STEPS = {False: "exact", True: "fast"}
#: the control: the exact step on the same field with every mobile floe's
#: velocity nudged at reset by a normal variate of this standard deviation
#: [m/s] (seeded by the field): two exact runs a rounding error apart
NUDGE = 1e-12
CONTROL = "nudged"

#: seed and concentration of the untimed warm-up episodes of a worker
WARMUP_SEED = 0
WARMUP_CONCENTRATION = 0.3
#: the full run's sizes
DEFAULTS = dict(seeds=10, concentrations=(0.2, 0.3, 0.4, 0.5), policies=POLICIES,
                seed=10_000, workers=2, speed_seed=10_001, rounds=3, late_after=100,
                small=False)
#: sizes of ``--quick`` (the small instance, iceenvs.facts.EnvFacts.small)
QUICK = dict(seeds=2, concentrations=(0.3,), rounds=1, late_after=20, small=True)


def _small_kwargs(small: bool) -> dict:
    """``gymnasium.make`` keywords of the environment's small instance, or none."""
    if not small:
        return {}
    from iceenvs.facts import env_facts

    return dict(env_facts(ENV_ID).small)


def env_kwargs(concentration: float | None, free_drift: bool, small: bool) -> dict:
    """The keywords of an episode: the instance (small or not), the step and,
    unless ``None``, the concentration, which the leaderboard sets the same way."""
    kwargs = {**_small_kwargs(small), "free_drift": bool(free_drift)}
    if concentration is not None:
        kwargs["concentration"] = float(concentration)
    return kwargs


class _PoolThreads:
    """``NUMBA_NUM_THREADS`` set to ``threads`` inside the block (what the
    processes started in it read when they start), as it was after."""

    def __init__(self, threads: int):
        self.threads = str(int(threads))

    def __enter__(self):
        self.saved = os.environ.get("NUMBA_NUM_THREADS")
        os.environ["NUMBA_NUM_THREADS"] = self.threads
        return self

    def __exit__(self, *exc):
        if self.saved is None:
            os.environ.pop("NUMBA_NUM_THREADS", None)
        else:
            os.environ["NUMBA_NUM_THREADS"] = self.saved


# ---------------------------------------------------------------------------
# the statistics, in worker processes
# ---------------------------------------------------------------------------

#: a worker's environments and policies, built once each
_WORKER: dict = {}


def _worker_policy(concentration: float, free_drift: bool, name: str, small: bool, seed: int):
    """The environment of a concentration and step, and the policy ``name``
    made for it, built on first use in this worker and kept, as
    :func:`agents.rollouts.evaluate_in_processes` keeps them: every episode
    starts from its own ``reset(seed)``, so what ran before does not matter."""
    from agents.baselines import make_baseline
    from agents.envs import make_checked_env

    key = (float(concentration), bool(free_drift), bool(small))
    envs = _WORKER.setdefault("envs", {})
    if key not in envs:
        envs[key] = make_checked_env(ENV_ID, env_kwargs(concentration, free_drift, small),
                                     seed=seed)
    policies = _WORKER.setdefault("policies", {})
    if (key, name) not in policies:
        policies[key, name] = make_baseline(name, envs[key], seed=seed)
    return envs[key], policies[key, name]


def init_worker(policies, small: bool, seed: int) -> None:
    """Start a worker: one Numba thread, then one untimed episode of every
    policy under each step on the small instance, so that every kernel is
    compiled or loaded before the first timed episode."""
    from agents.rollouts import run_episode

    numba.set_num_threads(1)
    for free_drift in STEPS:
        for name in policies:
            env, policy = _worker_policy(WARMUP_CONCENTRATION, free_drift, name, True, seed)
            run_episode(env, policy, WARMUP_SEED, None)


class Nudged:
    """An environment whose every reset nudges the velocity of each mobile
    floe by a normal variate of standard deviation :data:`NUDGE`, seeded by
    the reset's seed (the control of the statistics). Everything else is the
    wrapped environment's."""

    def __init__(self, env):
        self.env = env

    def __getattr__(self, name):
        return getattr(self.env, name)

    def reset(self, *, seed=None, options=None):
        obs, info = self.env.reset(seed=seed, options=options)
        sim = self.env.unwrapped.sim
        rng = np.random.default_rng([7, 0 if seed is None else int(seed)])
        mobile = ~np.asarray(sim.field.frozen)
        v = sim.velocities.copy()
        v[mobile] += rng.normal(0.0, NUDGE, (int(mobile.sum()), 2))
        sim.velocities = v
        return obs, info


def field_pair(concentration: float, name: str, field_seed: int, small: bool,
               seed: int) -> dict:
    """One field sailed by policy ``name`` with the exact step, the fast step
    and the control (:class:`Nudged`), one after the other in this worker
    (the order of the first two alternating with the seed, so that neither
    step always runs first): per run the episode of
    :func:`agents.rollouts.run_episode` without its per-step series, its wall
    time [s], the floes and, for the fast step, the engine's tally."""
    from agents.rollouts import run_episode

    out = {}
    order = list(STEPS) if field_seed % 2 == 0 else list(STEPS)[::-1]
    for free_drift, label in [(f, STEPS[f]) for f in order] + [(False, CONTROL)]:
        env, policy = _worker_policy(concentration, free_drift, name, small, seed)
        t0 = time.perf_counter()
        e = run_episode(Nudged(env) if label == CONTROL else env, policy, field_seed, None)
        wall = time.perf_counter() - t0
        sim = env.unwrapped.sim
        e = {k: v for k, v in e.items() if k not in ("rewards", "trace")}
        e.update(wall=wall, floes=int(sim.n_floes),
                 tally=[int(x) for x in sim.free_tally] if free_drift else None)
        out[label] = e
    return out


def run_statistics(st: dict, quiet: bool = False) -> list[dict]:
    """Every field of every concentration with every policy, both steps, over
    ``st["workers"]`` worker processes on one Numba thread each; one entry
    per field and policy: ``dict(concentration, policy, seed, exact, fast)``
    in the order of the concentrations, the policies and the seeds."""
    jobs = [(a, name, st["seed"] + k) for a in st["concentrations"] for name in st["policies"]
            for k in range(st["seeds"])]
    done = {}
    context = multiprocessing.get_context("spawn")
    with _PoolThreads(1), concurrent.futures.ProcessPoolExecutor(
            st["workers"], mp_context=context, initializer=init_worker,
            initargs=(tuple(st["policies"]), st["small"], st["seed"])) as pool, \
            harness.Progress(3 * len(jobs), SUITE, quiet, unit="episode") as bar:
        futures = {pool.submit(field_pair, a, name, s, st["small"], st["seed"]): (a, name, s)
                   for a, name, s in jobs}
        for future in concurrent.futures.as_completed(futures):
            done[futures[future]] = future.result()
            bar.advance(3)
    return [dict(concentration=a, policy=name, seed=s, **done[a, name, s])
            for a, name, s in jobs]


def _passes(relative: float, diff: float, sem: float) -> tuple[bool, bool]:
    """(within the relative tolerance of the mean, within the standard errors)."""
    return (bool(abs(relative) <= RELATIVE_TOLERANCE),
            bool(abs(diff) <= STANDARD_ERRORS * sem))


def _episodes(fields: list[dict], concentration: float, policy: str, step: str) -> list[dict]:
    return [f[step] for f in fields if f["concentration"] == concentration
            and f["policy"] == policy]


def metric_rows(fields: list[dict], st: dict, other: str = "fast") -> list[dict]:
    """Per concentration, policy and metric of :data:`METRICS`: the mean
    under the exact step and under ``other`` (the fast step, or the
    control), the difference of the means (other − exact, also relative to
    the exact mean), the standard error of the paired differences
    (:func:`agents.rollouts.compare`) and the two criteria. The keys say
    ``fast`` for the other either way."""
    from agents.rollouts import compare, stats

    rows = []
    for a in st["concentrations"]:
        for name in st["policies"]:
            exact = _episodes(fields, a, name, "exact")
            fast = _episodes(fields, a, name, other)
            for key, *_ in METRICS:
                mean_exact = stats([e["final"][key] for e in exact])["mean"]
                mean_fast = stats([e["final"][key] for e in fast])["mean"]
                paired = compare(fast, exact, key)
                diff, sem = paired["diff"], paired["sem"]
                relative = diff / abs(mean_exact) if mean_exact != 0 else (
                    0.0 if diff == 0 else math.inf)
                within_mean, within_se = _passes(relative, diff, sem)
                rows.append(dict(concentration=a, policy=name, metric=key,
                                 exact=mean_exact, fast=mean_fast, difference=diff,
                                 relative=relative, sem=sem, n=len(exact),
                                 within_mean=within_mean, within_se=within_se,
                                 passed=within_mean and within_se))
    return rows


def wall_rows(fields: list[dict], st: dict) -> list[dict]:
    """Per concentration and policy: the mean wall time and env steps of an
    episode under each step, and the exact mean over the fast one."""
    from agents.rollouts import stats

    rows = []
    for a in st["concentrations"]:
        for name in st["policies"]:
            w = {step: stats([e["wall"] for e in _episodes(fields, a, name, step)])
                 for step in STEPS.values()}
            n = {step: stats([e["length"] for e in _episodes(fields, a, name, step)])["mean"]
                 for step in STEPS.values()}
            rows.append(dict(concentration=a, policy=name, exact=w["exact"], fast=w["fast"],
                             steps_exact=n["exact"], steps_fast=n["fast"],
                             speedup=w["exact"]["mean"] / w["fast"]["mean"]))
    return rows


def route_choice(fields: list[dict], st: dict) -> list[dict]:
    """Per concentration and step: the lattice planner's mean impulse per
    metre over the straight line's (the leaderboard's ratio of means,
    :func:`agents.leaderboard.summarise_board`), and the mean of the
    per-field ratios with its standard error. Empty unless both ran."""
    from agents.leaderboard import summarise_board

    if not {"straight", "lattice"} <= set(st["policies"]):
        return []
    rows = []
    for a in st["concentrations"]:
        row = dict(concentration=a)
        for step in STEPS.values():
            board = {f"{a:g}": {name: _episodes(fields, a, name, step)
                                for name in ("straight", "lattice")}}
            s = summarise_board(board)[f"{a:g}"]["lattice"]
            row[step] = dict(ratio_of_means=s["ipm_ratio_of_means"],
                             per_field=s["ratio_impulse_per_metre"],
                             path_ratio=s["path_ratio_of_means"])
        rows.append(row)
    return rows


def field_records(fields: list[dict]) -> list[dict]:
    """The fields as the record keeps them: per step the metrics of
    :data:`METRICS`, the wall time, the env steps, the floes and the tally."""
    keep = [key for key, *_ in METRICS]
    out = []
    for f in fields:
        entry = dict(concentration=f["concentration"], policy=f["policy"], seed=f["seed"])
        for step in (*STEPS.values(), CONTROL):
            e = f[step]
            entry[step] = dict({k: e["final"][k] for k in keep}, wall=e["wall"],
                               length=e["length"], floes=e["floes"], tally=e["tally"])
        out.append(entry)
    return out


# ---------------------------------------------------------------------------
# the speed, in a fresh process
# ---------------------------------------------------------------------------

def _timed_episode(env, seed: int, late_after: int) -> dict:
    """One zero-action episode from ``reset(seed)``: the wall time of every
    env step (the reset left out) and the floes the step integrated at the
    end of each (awake or engaged, ``sim.n_awake``)."""
    env.reset(seed=seed)
    zero = np.zeros(env.action_space.shape, env.action_space.dtype)
    times, awake = [], []
    while True:
        t0 = time.perf_counter()
        _, _, term, trunc, _ = env.step(zero)
        times.append(time.perf_counter() - t0)
        awake.append(int(env.unwrapped.sim.n_awake))
        if term or trunc:
            break
    sim = env.unwrapped.sim
    late = times[late_after:]
    return dict(steps=len(times), seconds=float(np.sum(times)),
                rate=len(times) / float(np.sum(times)),
                late_steps=len(late), late_ms=1e3 * float(np.mean(late)) if late else None,
                awake_mean=float(np.mean(awake)),
                tally=[int(x) for x in sim.free_tally] if sim.free_drift else None)


def speed_child(st: dict) -> dict:
    """The speed measurement (see :data:`DESCRIPTION`) in this process, on
    one Numba thread: an environment per step, one untimed episode of each
    (compilation and kernel loading), then ``st["rounds"]`` rounds of the
    timed episode, the steps taking turns."""
    from agents.envs import make_checked_env

    numba.set_num_threads(1)
    seed, late_after = st["speed_seed"], st["late_after"]
    envs = {step: make_checked_env(ENV_ID, env_kwargs(None, free_drift, st["small"]),
                                   seed=seed) for free_drift, step in STEPS.items()}
    try:
        for env in envs.values():
            _timed_episode(env, seed, late_after)                        # untimed
        runs = [lambda env=env: _timed_episode(env, seed, late_after) for env in envs.values()]
        rounds = harness.interleaved_rounds(runs, st["rounds"])
        u = envs["exact"].unwrapped
        concentration = float(u.episode["concentration"])
        floes = int(u.sim.n_floes)
    finally:
        for env in envs.values():
            env.close()
    return dict(seed=seed, late_after=late_after, concentration=concentration,
                drawn="concentration" not in env_kwargs(None, False, st["small"]), floes=floes,
                rounds=dict(zip(envs, rounds)))


def summarise_speed(speed: dict) -> dict:
    """Per step the best round and the slowest of the rate and of the late
    ms per env step, and the fast step's gain on each (best over best)."""
    out = {}
    for step, rounds in speed["rounds"].items():
        rates = [r["rate"] for r in rounds]
        late = [r["late_ms"] for r in rounds if r["late_ms"] is not None]
        tally = rounds[0]["tally"]
        out[step] = dict(rate=max(rates), slowest_rate=min(rates),
                         late_ms=min(late) if late else None,
                         slowest_late_ms=max(late) if late else None,
                         steps=rounds[0]["steps"], late_steps=rounds[0]["late_steps"],
                         awake_mean=float(np.mean([r["awake_mean"] for r in rounds])),
                         engaged_per_step=tally[2] / tally[3] if tally and tally[3] else None,
                         windows=tally[0] if tally else None,
                         ended_by_guard=tally[1] if tally else None,
                         substeps=tally[3] if tally else None)
    e, f = out["exact"], out["fast"]
    out["gain"] = dict(rate=f["rate"] / e["rate"],
                       late=(e["late_ms"] / f["late_ms"]
                             if e["late_ms"] and f["late_ms"] else None))
    return out


# ---------------------------------------------------------------------------
# the record
# ---------------------------------------------------------------------------

def _percent(x: float, signed: bool = True) -> str:
    if x is None or not math.isfinite(x):
        return "–"
    return f"{100 * x:+.2f} %" if signed else f"{100 * x:.2f} %"


def _spread(best: float, slowest: float, higher_is_better: bool) -> str:
    if best is None or slowest is None:
        return "–"
    worse = 1 - slowest / best if higher_is_better else slowest / best - 1
    return f"{'−' if higher_is_better else '+'}{100 * worse:.0f} %"


def speed_table(speed: dict, summary: dict, rounds: int) -> dict:
    """Env steps/s and late ms per env step under each step, and the floes
    each step integrates."""
    rows = []
    for step in STEPS.values():
        s = summary[step]
        rows.append([step, s["rate"], _spread(s["rate"], s["slowest_rate"], True),
                     s["late_ms"], _spread(s["late_ms"], s["slowest_late_ms"], False),
                     s["awake_mean"], s["engaged_per_step"], speed["floes"]])
    g = summary["gain"]
    rows.append(["fast over exact", f"{g['rate']:.2f}× the rate", "",
                 "–" if g["late"] is None else f"{1 / g['late']:.2f}× the time",
                 "", "", "", ""])
    f = summary["fast"]
    guard = ("" if not f["windows"] else
             f" The fast step's tally: {f['windows']} windows over {f['substeps']} substeps, "
             f"{100 * f['ended_by_guard'] / f['windows']:.0f} % of them ended by a guard.")
    return harness.table(
        f"Speed: one straight-line episode, seed {speed['seed']}, A = "
        f"{speed['concentration']:.3f} "
        f"({'as the environment draws it' if speed['drawn'] else 'set by the instance'}), "
        f"{speed['floes']} floes, "
        f"one thread (best of {rounds} round{'s' * (rounds != 1)})",
        ["step", "env steps/s (whole episode)", "slowest round",
         f"ms per env step after step {speed['late_after']}", "slowest round",
         "floes awake or engaged at the end of an env step (mean)",
         "engaged floe-steps per substep (tally)", "floes"], rows,
        f"Env steps/s: the {f['steps']} env steps of the episode over their own wall time, "
        f"the reset left out; the late figure is the mean over its last {f['late_steps']} "
        f"steps. Slowest round: how much worse than the best the slowest round was. Floes "
        f"awake (exact step: those not at rest, `sim.n_awake`) or engaged (fast step: those "
        f"of the last window that take the contact step) at the end of each env step, "
        f"averaged over the episode; engaged floe-steps per substep from the fast step's "
        f"`sim.free_tally`, over the whole episode.{guard}")


def statistics_table(rows: list[dict], st: dict, other: str = "fast") -> dict:
    """The means under the exact step and ``other`` (the fast step or the
    control) and the two criteria, per concentration, policy and metric."""
    labels = {key: (f"{label} [{unit}]" if unit else label, scale)
              for key, label, scale, unit in METRICS}
    body = []
    for r in rows:
        label, scale = labels[r["metric"]]
        body.append([r["concentration"], r["policy"], label, r["exact"] / scale,
                     r["fast"] / scale, r["difference"] / scale, _percent(r["relative"]),
                     r["sem"] / scale, "yes" if r["within_mean"] else "**no**",
                     "yes" if r["within_se"] else "**no**",
                     "pass" if r["passed"] else "**fail**"])
    failed = [r for r in rows if not r["passed"]]
    verdict = (f"All {len(rows)} rows pass." if not failed else
               f"{len(rows) - len(failed)} of {len(rows)} rows pass; {len(failed)} fail: "
               + "; ".join(f"A = {r['concentration']:g}, {r['policy']}, {r['metric']}"
                           for r in failed) + ".")
    if other == CONTROL:
        title = (f"The control: the exact step against itself, the velocity of every floe "
                 f"nudged by {NUDGE:g} m/s at reset, means over {st['seeds']} fields")
    else:
        title = f"Exact and fast step: means over {st['seeds']} fields"
    return harness.table(
        title,
        ["A", "policy", "metric", "mean, exact", f"mean, {other}", f"{other} − exact",
         "relative to exact", "SE of paired differences",
         f"within {100 * RELATIVE_TOLERANCE:g} % of the mean",
         f"within {STANDARD_ERRORS:g} SE", "both"], body,
        f"{other} − exact: the difference of the means, which is the mean of the per-field "
        f"differences; SE: the standard error of that mean over the {st['seeds']} fields "
        f"(paired: the same field under both). A row passes when the difference is "
        f"within {100 * RELATIVE_TOLERANCE:g} % of the exact mean and within "
        f"{STANDARD_ERRORS:g} standard errors. {verdict}")


def wall_table(rows: list[dict], st: dict) -> dict:
    """The mean wall time of an episode under each step."""
    body = [[r["concentration"], r["policy"], r["steps_exact"], r["exact"]["mean"],
             r["fast"]["mean"], f"{r['speedup']:.2f}×"] for r in rows]
    return harness.table(
        "Wall time of an episode",
        ["A", "policy", "env steps (mean)", "exact [s]", "fast [s]", "exact over fast"], body,
        f"Means over the {st['seeds']} fields of the statistics, each episode in a worker "
        f"process on one Numba thread, {st['workers']} workers side by side on the machine; "
        f"the reset and the policy's decisions (the lattice planner's plans) are included.")


def route_table(rows: list[dict], st: dict) -> dict:
    """The lattice planner's impulse per metre over the straight line's,
    under each step."""
    def below(x):
        return "yes" if x < 1.0 else "**no**"

    body = []
    for r in rows:
        e, f = r["exact"], r["fast"]
        body.append([r["concentration"], e["ratio_of_means"], f["ratio_of_means"],
                     f"{e['per_field']['mean']:.3f} ± {e['per_field']['sem']:.3f}",
                     f"{f['per_field']['mean']:.3f} ± {f['per_field']['sem']:.3f}",
                     f"{below(e['ratio_of_means'])} / {below(f['ratio_of_means'])}"])
    return harness.table(
        "Does route choice pay under each step?",
        ["A", "lattice / straight, exact", "lattice / straight, fast",
         "per field, exact (mean ± SE)", "per field, fast (mean ± SE)",
         "below 1: exact / fast"], body,
        f"The lattice planner's mean ice impulse per metre over the straight line's on the "
        f"same {st['seeds']} fields (the leaderboard's ratio of means), and the mean of the "
        f"per-field ratios. The leaderboard finds it below 1 at A = 0.2–0.4.")


def parse_parts(text: str | None) -> list[str]:
    """The parts of ``--parts`` in the order of :data:`PARTS`; ``None``: both.

    Raises
    ------
    ValueError
        If a name is unknown, or none is given.
    """
    return harness.pick_names(text, PARTS, "part")


def parse_concentrations(text: str) -> tuple[float, ...]:
    """The concentrations of ``--concentrations`` (``"0.2,0.3"``).

    Raises
    ------
    ValueError
        If one is not a number in (0, 1), or none is given.
    """
    try:
        values = tuple(float(a) for a in str(text).split(",") if a.strip())
    except ValueError:
        raise ValueError(f"--concentrations takes numbers separated by commas, got "
                         f"{text!r}") from None
    if not values or not all(0.0 < a < 1.0 for a in values):
        raise ValueError(f"--concentrations must name concentrations in (0, 1), got {text!r}")
    return values


def parse_policies(text: str) -> tuple[str, ...]:
    """The policies of ``--policies``: baselines of the environment
    (:func:`agents.baselines.baseline_names`), in the order given.

    Raises
    ------
    ValueError
        If one is unknown, or none is given.
    """
    from agents.baselines import baseline_names

    valid = baseline_names(ENV_ID)
    names = tuple(dict.fromkeys(n.strip() for n in str(text).split(",") if n.strip()))
    unknown = [n for n in names if n not in valid]
    if unknown or not names:
        raise ValueError(f"unknown policy(s) {', '.join(unknown) or '(none)'}; known: "
                         f"{', '.join(valid)}")
    return names


def main(argv=None, prog: str | None = None) -> int:
    p = harness.suite_parser(SUITE, TITLE + ": " + DESCRIPTION, prog)
    p.add_argument("--parts", default=None,
                   help="what to measure, comma-separated: " + ", ".join(PARTS)
                        + " (default: both)")
    p.add_argument("--seeds", type=int, default=None,
                   help=f"fields per concentration and policy (default {DEFAULTS['seeds']})")
    p.add_argument("--concentrations", default=None,
                   help="ice concentrations, comma-separated (default 0.2,0.3,0.4,0.5)")
    p.add_argument("--policies", default=None,
                   help="baselines, comma-separated (default straight,lattice)")
    p.add_argument("--seed", type=int, default=None,
                   help=f"seed of the first field, and of the policies "
                        f"(default {DEFAULTS['seed']})")
    p.add_argument("--workers", type=int, default=None,
                   help=f"worker processes of the statistics (default {DEFAULTS['workers']})")
    p.add_argument("--speed-seed", type=int, default=None,
                   help=f"seed of the timed episode (default {DEFAULTS['speed_seed']})")
    p.add_argument("--rounds", type=int, default=None,
                   help=f"rounds of the timed episode (default {DEFAULTS['rounds']})")
    p.add_argument("--late-after", type=int, default=None,
                   help=f"env steps before the late part of the timed episode "
                        f"(default {DEFAULTS['late_after']})")
    args, argv = harness.parse(p, argv)
    st = harness.settings(args, DEFAULTS, QUICK, ("seeds", "seed", "workers", "speed_seed",
                                                  "rounds", "late_after"))
    if st["seeds"] < 2:
        p.error(f"--seeds must be at least 2 (standard errors), got {st['seeds']}")
    if min(st["workers"], st["rounds"]) < 1 or st["late_after"] < 0:
        p.error("--workers and --rounds must be at least 1, --late-after at least 0")
    try:
        parts = parse_parts(args.parts)
        if args.concentrations is not None:
            st["concentrations"] = parse_concentrations(args.concentrations)
        if args.policies is not None:
            st["policies"] = parse_policies(args.policies)
    except ValueError as exc:
        p.error(str(exc))

    t0 = time.perf_counter()
    tables, data = [], dict(parts=parts, settings=st, quick=args.quick)
    if "speed" in parts:
        if not args.quiet:
            print("speed: one episode per step and round, in a fresh process ...", flush=True)
        speed = harness.spawn_call(speed_child, st, threads=1)
        summary = summarise_speed(speed)
        data["speed"] = dict(speed, summary=summary)
        tables.append(speed_table(speed, summary, st["rounds"]))
        if not args.quiet:
            print(f"  env steps/s: exact {summary['exact']['rate']:.3g}, fast "
                  f"{summary['fast']['rate']:.3g} ({summary['gain']['rate']:.2f}×)", flush=True)
    if "statistics" in parts:
        fields = run_statistics(st, args.quiet)
        rows = metric_rows(fields, st)
        control = metric_rows(fields, st, CONTROL)
        walls = wall_rows(fields, st)
        routes = route_choice(fields, st)
        data["statistics"] = dict(rows=rows, wall=walls, route_choice=routes,
                                  passed=sum(r["passed"] for r in rows), total=len(rows),
                                  control=control,
                                  control_passed=sum(r["passed"] for r in control),
                                  fields=field_records(fields))
        tables.append(statistics_table(rows, st))
        tables.append(statistics_table(control, st, CONTROL))
        if routes:
            tables.append(route_table(routes, st))
        tables.append(wall_table(walls, st))
    record = harness.make_record(
        SUITE, TITLE, DESCRIPTION, harness.command_line(SUITE, argv), tables, data,
        time.perf_counter() - t0, machine=harness.machine_info(1))
    harness.finish(args, record)
    return 0


if __name__ == "__main__":
    sys.exit(main())
