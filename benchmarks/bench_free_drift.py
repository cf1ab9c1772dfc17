"""The ship's steps against the exact one, an equivalence test:
``python -m benchmarks.bench_free_drift`` (``seaice bench free_drift``).

    python -m benchmarks.bench_free_drift [--parts statistics,speed] [--seeds 40]
                                    [--concentrations 0.2,0.3,0.4,0.5]
                                    [--policies straight,swath,lattice]
                                    [--variants fast,soft-0.1,soft-0.01] [--seed 10000]
                                    [--workers 2] [--speed-seed 10001] [--rounds 3]
                                    [--late-after 100] [--fields PATH]
                                    [--quiet] [--quick] [--json PATH | --no-json]

The episodes of the statistics are shared among ``--workers`` processes, each
on one Numba thread; the speed is measured in a fresh process of its own, on
one thread, before them.
"""
from __future__ import annotations

import concurrent.futures
import json
import math
import multiprocessing
import os
import sys
import time

import numba
import numpy as np

from . import harness

SUITE = "free_drift"
TITLE = "The ship's fast step and soft ice against the exact step: an equivalence test"
DESCRIPTION = """
Whether the cheaper steps of the ship environments give the exact step's
episodes in distribution, and what they save. The **fast step**
(`free_drift=True`) lets the floes that provably touch nothing during a
window of steps drift in closed form: the same physics up to rounding.
**Soft ice** (`stiffness_scale` 0.1 or 0.01, with the fast step) lowers
Young's modulus, so that the Hertz time step grows as its −2/5 power: the
impulse a binary collision exchanges does not depend on it, its peak force
and duration do. Granular contact dynamics are chaotic, so an episode run
with each step from the same field follows the exact one for a while and
then another trajectory: only statistics over many fields can agree.

* **The episodes.** `iceenvs/ShipNavigation-v1` at ice concentrations
  A = 0.2, 0.3, 0.4 and 0.5 (the environment's `concentration`, set as the
  leaderboard sets it), 80 fields each, field k seeded 20000 + k (fields of
  their own, apart from the leaderboard's, seeded 10000 + k), with three of
  the leaderboard's policies: the straight line (`straight`), the swath
  planner (`swath`) and the lattice planner (`lattice`, `agents.planners`).
  (`--env` runs the same test on ShipNavigation-v0 at A = 0.2, 0.4, 0.6
  with the straight line and the lattice planner, or on ShipBeset-v0 at
  A = 0.6, 0.675, 0.75 with the straight line and the reactive controller,
  and writes its record beside this one.) Every field is sailed by every
  policy under the exact step (`free_drift=False`), the fast step and the
  two soft ices, and a last time under the **control**: the exact step with
  every mobile floe's velocity nudged at reset by a normal variate of
  standard deviation 1e-12 m/s (seeded by the field), two exact runs a
  rounding error apart. From each episode's final info: the ice impulse per
  metre, the collisions, the energy given to the ice and the path length.
* **The equivalence test** (stated before the episodes were run). For each
  candidate (the fast step, each soft ice, and the control), concentration,
  policy and metric: the per-field differences candidate − exact, and a 90 %
  confidence interval of their 20 %-trimmed mean (Yuen's interval: the
  mean of the middle 60 % of the differences, its standard error from the
  winsorized ones). The candidate is equivalent on that row when the whole
  interval lies within ±5 % of the exact mean (two one-sided tests at the
  5 % level). A row is unresolved where the control's own interval does not
  lie within the margin: there these fields cannot tell a rounding error
  from a difference of 5 %. The trimmed mean and the 80 fields come from a
  pilot (the record `free_drift-pilot` below, `--statistic control`: 40 of
  the leaderboard's fields, the mean where the control resolved the margin
  with it). There one or two fields held most of the spread of the
  differences in some rows, a large floe struck in one run and missed in
  the other or a planner's route flipped: chaos, not a difference of the
  steps, and on whichever step it fell it widened the interval of the
  mean past the margin. Two steps equal in distribution give differences
  symmetric about zero, whose trimmed mean estimates the same centre as the
  mean while a few such fields cannot move it; its intervals reached about
  the margin with 40 fields, and 80 halve their variance. The intervals of
  the mean are given beside.
* **The leaderboard's conclusions under each step.** Whether route choice
  pays (the best planner meets at most 0.7 times the straight line's
  impulse per metre, ratio of means, sailing at most 10 % further), and the
  order of the three policies by their impulse per metre over all
  concentrations together, with the paired difference of the two planners.
* **Sustained rates.** The env steps of the straight-line episodes over
  their wall time (reset included), per concentration and over all four
  together: whole transits, in worker processes on one Numba thread each,
  the workers side by side on the machine.
* **Speed on one thread.** One straight-line episode (zero action) of
  ShipNavigation-v1, seed 10001, its concentration as the environment draws
  it, in a fresh process on one Numba thread: env steps/s over the whole
  episode and the mean wall time of an env step after env step 100, under
  each step, the steps taking turns round after round (three rounds; each
  figure is the best round, with the slowest beside it), after one untimed
  episode of each. Beside them the floes each step integrates.

The episodes of the statistics run in worker processes, each warmed up
before its first episode by one untimed episode of every policy under each
step on the environment's small instance, so that no compilation falls into
an episode's wall time. Every random number is seeded: the fields by their
seeds, the policies by the first field's.
"""

PILOT_DESCRIPTION = """
The pilot of the equivalence test above (`--statistic control`), which
chose its statistic and its number of fields: the same steps, policies,
control, metrics and margin, on 40 of the leaderboard's fields per
concentration (field k seeded 10000 + k). Its rule for a row's statistic:
the mean (Student's interval) where the control's interval of the mean lies
within the margin, the 20 %-trimmed mean (Yuen's) elsewhere, unresolved
where neither does. In some rows one or two fields held most of the spread
of the differences, and where the control happened to have none the mean
was chosen and the candidate's interval widened past the margin. Its
statistics can be computed again from its saved runs (`--runs`, as the
command below did) or from new ones.
"""

EXTENSION_DESCRIPTION = """
A row of the equivalence test above that its fields left not shown
equivalent (or unresolved) is sailed again on more fields, field k seeded
20000 + k beyond those of the test, under the exact step, the step in
question and the control, and judged on all its fields together with a
95 % interval of the 20 %-trimmed mean (two one-sided tests at 2.5 %), so
that the two looks at the row keep the chance of a false equivalence
under 7.5 %. The step counts as equivalent on the row where this interval
lies within the margin (`benchmarks.bench_free_drift.supports`). The other
metrics of the same fields come with it.
"""

#: the environment whose episodes are compared by default
ENV_ID = "iceenvs/ShipNavigation-v1"
#: the ship environments the suite can compare (``--env``), each with its
#: concentrations and policies by default (the first is the one the others
#: are compared with in the leaderboard's conclusions)
ENVS = {"iceenvs/ShipNavigation-v1": dict(concentrations=(0.2, 0.3, 0.4, 0.5),
                                          policies=("straight", "swath", "lattice")),
        "iceenvs/ShipNavigation-v0": dict(concentrations=(0.2, 0.4, 0.6),
                                          policies=("straight", "lattice")),
        "iceenvs/ShipBeset-v0": dict(concentrations=(0.6, 0.675, 0.75),
                                     policies=("straight", "reactive"))}
#: the parts of the suite
PARTS = ("statistics", "speed")
#: the policies compared by default, as the leaderboard names them
POLICIES = ("straight", "swath", "lattice")
#: the metrics of each episode's final info: (key, label, scale, unit)
METRICS = (("impulse_per_metre", "impulse per metre", 1e3, "kN s/m"),
           ("collisions", "collisions", 1.0, ""),
           ("energy_to_ice", "energy to the ice", 1e6, "MJ"),
           ("path_length", "path length", 1.0, "m"))
#: what a run keeps of its episode's final info: the metrics, and what the
#: leaderboard's summary reads besides them
KEPT = tuple(dict.fromkeys([key for key, *_ in METRICS] + ["success", "mean_impulse",
                                                           "max_impulse"]))
#: the steps, by name: the environment's keywords of each (besides the
#: concentration); the first is the reference
VARIANTS = {"exact": dict(free_drift=False),
            "fast": dict(free_drift=True),
            "soft-0.1": dict(free_drift=True, stiffness_scale=0.1),
            "soft-0.01": dict(free_drift=True, stiffness_scale=0.01)}
REFERENCE = "exact"
#: the candidates compared with the reference by default
CANDIDATES = ("fast", "soft-0.1", "soft-0.01")
#: the control: the reference step on the same field with every mobile floe's
#: velocity nudged at reset by a normal variate of this standard deviation
#: [m/s] (seeded by the field): two exact runs a rounding error apart
NUDGE = 1e-12
CONTROL = "nudged"
#: the equivalence margin, as a fraction of the reference's mean
MARGIN = 0.05
#: the confidence of the interval (two one-sided tests at (1 − it)/2 each)
CONFIDENCE = 0.90
#: the fraction trimmed from each end by the robust statistic
TRIM = 0.2
#: the verdicts of a row
PASS, FAIL, UNRESOLVED = "pass", "**fail**", "unresolved"
#: the share of the rows the control must resolve, and the step pass, for
#: the record to support the step as an environment's default (:func:`supports`)
RESOLVED = 0.9
#: the choices of the statistic (``--statistic``): the trimmed mean on every
#: row, or the one the control decides row by row
STATISTICS = ("trimmed", "control")

#: seed of the untimed warm-up episodes of a worker (at the environment's
#: first concentration)
WARMUP_SEED = 0
#: the full run's sizes
DEFAULTS = dict(env=ENV_ID, seeds=80, concentrations=ENVS[ENV_ID]["concentrations"],
                policies=POLICIES, variants=CANDIDATES, seed=20_000, workers=2,
                speed_seed=10_001, rounds=3, late_after=100, small=False)
#: sizes of ``--quick`` (the small instance, iceenvs.facts.EnvFacts.small)
QUICK = dict(seeds=5, variants=("fast", "soft-0.01"), rounds=1, late_after=20, small=True)


def _small_kwargs(small: bool, env_id: str = ENV_ID) -> dict:
    """``gymnasium.make`` keywords of the environment's small instance, or none."""
    if not small:
        return {}
    from iceenvs.facts import env_facts

    return dict(env_facts(env_id).small)


def env_kwargs(concentration: float | None, variant: str, small: bool,
               env_id: str = ENV_ID) -> dict:
    """The keywords of an episode: the instance (small or not), the step of
    ``variant`` (a key of :data:`VARIANTS`) and, unless ``None``, the
    concentration, which the leaderboard sets the same way."""
    kwargs = {**_small_kwargs(small, env_id), **VARIANTS[variant]}
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
# the episodes, in worker processes
# ---------------------------------------------------------------------------

#: a worker's environments and policies, built once each
_WORKER: dict = {}


def _worker_policy(env_id: str, concentration: float, variant: str, name: str, small: bool,
                   seed: int):
    """The environment of a concentration and step, and the policy ``name``
    made for it, built on first use in this worker and kept, as
    :func:`agents.rollouts.evaluate_in_processes` keeps them: every episode
    starts from its own ``reset(seed)``, so what ran before does not matter."""
    from agents.baselines import make_baseline
    from agents.envs import make_checked_env

    key = (env_id, float(concentration), variant, bool(small))
    envs = _WORKER.setdefault("envs", {})
    if key not in envs:
        envs[key] = make_checked_env(env_id, env_kwargs(concentration, variant, small, env_id),
                                     seed=seed)
    policies = _WORKER.setdefault("policies", {})
    if (key, name) not in policies:
        policies[key, name] = make_baseline(name, envs[key], seed=seed)
    return envs[key], policies[key, name]


def init_worker(env_id: str, policies, variants, small: bool, seed: int) -> None:
    """Start a worker: one Numba thread, then one untimed episode of every
    policy under each step on the small instance, so that every kernel is
    compiled or loaded before the first timed episode."""
    from agents.rollouts import run_episode

    numba.set_num_threads(1)
    for variant in variants:
        for name in policies:
            concentration = ENVS[env_id]["concentrations"][0]
            env, policy = _worker_policy(env_id, concentration, variant, name, True, seed)
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


def run_order(variants, field_seed: int) -> list[str]:
    """The runs of a field, the reference's and the candidates', then the
    control's: the steps rotated by the field's seed, so that none always
    runs first (the order changes nothing but the machine's state)."""
    steps = [REFERENCE, *[v for v in variants if v != REFERENCE]]
    k = field_seed % len(steps)
    return steps[k:] + steps[:k] + [CONTROL]


def field_runs(env_id: str, concentration: float, name: str, field_seed: int, small: bool,
               seed: int, variants) -> dict:
    """One field sailed by policy ``name`` under the reference step, each of
    ``variants`` and the control (:class:`Nudged`), one after the other in
    this worker: per run the metrics of :data:`METRICS`, the return, the
    env steps, the wall time [s] of the episode (reset and decisions
    included), the floes and, for a fast step, the engine's tally."""
    from agents.rollouts import run_episode

    out = {}
    for label in run_order(variants, field_seed):
        variant = REFERENCE if label == CONTROL else label
        env, policy = _worker_policy(env_id, concentration, variant, name, small, seed)
        t0 = time.perf_counter()
        e = run_episode(Nudged(env) if label == CONTROL else env, policy, field_seed, None)
        wall = time.perf_counter() - t0
        sim = env.unwrapped.sim
        out[label] = dict({key: float(e["final"][key]) for key in KEPT},
                          ret=float(e["ret"]), length=int(e["length"]), wall=wall,
                          floes=int(sim.n_floes),
                          tally=[int(x) for x in sim.free_tally] if sim.free_drift else None)
    return out


def read_runs(paths, st: dict) -> list[dict]:
    """The fields' runs of JSON files written by ``--fields`` (one path or
    several, taken together), checked to hold every field, policy and step
    of the settings ``st``.

    Raises
    ------
    ValueError
        If one is missing.
    """
    paths = [paths] if isinstance(paths, (str, os.PathLike)) else list(paths)
    fields = []
    for one in paths:
        with open(one, encoding="utf-8") as fh:
            fields += json.load(fh)
    path = ", ".join(str(x) for x in paths)
    have = {(f["concentration"], f["policy"], f["seed"]) for f in fields}
    want = [(a, name, st["seed"] + k) for a in st["concentrations"] for name in st["policies"]
            for k in range(st["seeds"])]
    missing = [w for w in want if w not in have]
    steps = [REFERENCE, *st["variants"], CONTROL]
    if missing or any(step not in f for f in fields for step in steps):
        raise ValueError(f"--runs {path}: not the runs of these settings (missing "
                         f"{missing[:3] or 'a step'})")
    return [f for w in want for f in fields
            if (f["concentration"], f["policy"], f["seed"]) == w]


def run_statistics(st: dict, quiet: bool = False) -> list[dict]:
    """Every field of every concentration with every policy under every step,
    over ``st["workers"]`` worker processes on one Numba thread each; one
    entry per field and policy, ``dict(concentration, policy, seed, <step>:
    run, ...)``, in the order of the concentrations, the policies and the
    seeds."""
    jobs = [(a, name, st["seed"] + k) for a in st["concentrations"] for name in st["policies"]
            for k in range(st["seeds"])]
    runs = 2 + len(st["variants"])
    done = {}
    context = multiprocessing.get_context("spawn")
    with _PoolThreads(1), concurrent.futures.ProcessPoolExecutor(
            st["workers"], mp_context=context, initializer=init_worker,
            initargs=(st["env"], tuple(st["policies"]), (REFERENCE, *st["variants"]),
                      st["small"], st["seed"])) as pool, \
            harness.Progress(runs * len(jobs), SUITE, quiet, unit="episode") as bar:
        futures = {pool.submit(field_runs, st["env"], a, name, s, st["small"], st["seed"],
                               tuple(st["variants"])): (a, name, s)
                   for a, name, s in jobs}
        for future in concurrent.futures.as_completed(futures):
            done[futures[future]] = future.result()
            bar.advance(runs)
    return [dict(concentration=a, policy=name, seed=s, **done[a, name, s])
            for a, name, s in jobs]


# ---------------------------------------------------------------------------
# the equivalence test
# ---------------------------------------------------------------------------

def mean_interval(d, confidence: float = CONFIDENCE) -> tuple[float, float, float]:
    """(mean, lower, upper): the mean of the differences ``d`` and its
    two-sided ``confidence`` interval (Student's t, n − 1 degrees of
    freedom)."""
    from scipy import stats

    d = np.asarray(d, dtype=float)
    n = d.size
    centre = float(np.mean(d))
    half = float(stats.t.ppf(0.5 + 0.5 * confidence, n - 1) * np.std(d, ddof=1) / math.sqrt(n))
    return centre, centre - half, centre + half


def trimmed_interval(d, trim: float = TRIM,
                     confidence: float = CONFIDENCE) -> tuple[float, float, float]:
    """(trimmed mean, lower, upper): the mean of the differences ``d`` with
    g = ⌊trim n⌋ taken off each end, and Yuen's two-sided ``confidence``
    interval: standard error s_w / ((1 − 2 g/n) √n), s_w the standard
    deviation of the winsorized differences, n − 2g − 1 degrees of
    freedom."""
    from scipy import stats

    x = np.sort(np.asarray(d, dtype=float))
    n = x.size
    g = int(math.floor(trim * n))
    h = n - 2 * g
    centre = float(np.mean(x[g:n - g]))
    w = x.copy()
    if g > 0:
        w[:g] = x[g]
        w[n - g:] = x[n - g - 1]
    se = float(np.std(w, ddof=1)) / ((h / n) * math.sqrt(n))
    half = float(stats.t.ppf(0.5 + 0.5 * confidence, h - 1) * se)
    return centre, centre - half, centre + half


def within(interval, scale: float, margin: float = MARGIN) -> bool:
    """Whether the interval (centre, lower, upper) lies within ±``margin``
    of ``scale`` (the reference's mean)."""
    return bool(abs(interval[1]) < margin * scale and abs(interval[2]) < margin * scale)


def relative(interval, scale: float) -> list[float]:
    """An interval (centre, lower, upper) over ``scale`` (a reference's
    mean; a zero scale gives 0 for zeros and ±∞ otherwise)."""
    if scale > 0:
        return [v / scale for v in interval]
    return [0.0 if v == 0 else math.copysign(math.inf, v) for v in interval]


def _runs(fields: list[dict], concentration: float, policy: str, step: str) -> list[dict]:
    return [f[step] for f in fields if f["concentration"] == concentration
            and f["policy"] == policy]


def equivalence_rows(fields: list[dict], st: dict) -> list[dict]:
    """Per concentration, policy and metric of :data:`METRICS`: the
    reference's mean, the statistic of the row (``st["statistic"]``:
    ``"trimmed"``, the trimmed mean on every row, or ``"control"``, the one
    the control decides: ``"mean"`` where it resolves the margin, else
    ``"trimmed"``), None where the control's interval of that statistic does
    not lie within the margin (the row is unresolved), and for the control
    and each candidate the per-field differences' intervals of the mean and
    of the trimmed mean, relative to the reference's mean, and the verdict
    (:data:`PASS`, :data:`FAIL` or :data:`UNRESOLVED`)."""
    rows = []
    for a in st["concentrations"]:
        for name in st["policies"]:
            ref = _runs(fields, a, name, REFERENCE)
            for key, *_ in METRICS:
                x = np.array([r[key] for r in ref])
                scale = abs(float(np.mean(x)))
                out = {}
                for label in (CONTROL, *st["variants"]):
                    d = np.array([r[key] for r in _runs(fields, a, name, label)]) - x
                    level = st.get("confidence", CONFIDENCE)
                    m, t = mean_interval(d, level), trimmed_interval(d, confidence=level)
                    out[label] = dict(mean=relative(m, scale), trimmed=relative(t, scale),
                                      mean_mean=float(np.mean(x + d)),
                                      within_mean=within(m, scale),
                                      within_trimmed=within(t, scale))
                c = out[CONTROL]
                if st.get("statistic", "trimmed") == "trimmed":
                    statistic = "trimmed" if c["within_trimmed"] else None
                else:
                    statistic = ("mean" if c["within_mean"] else
                                 "trimmed" if c["within_trimmed"] else None)
                for o in out.values():
                    o["verdict"] = (UNRESOLVED if statistic is None else
                                    PASS if o[f"within_{statistic}"] else FAIL)
                rows.append(dict(concentration=a, policy=name, metric=key,
                                 reference=float(np.mean(x)), n=int(x.size),
                                 statistic=statistic, runs=out))
    return rows


def verdicts(rows: list[dict], labels) -> dict:
    """Per label: the rows that pass, fail and are unresolved."""
    out = {}
    for label in labels:
        v = [r["runs"][label]["verdict"] for r in rows]
        out[label] = dict(passed=v.count(PASS), failed=v.count(FAIL),
                          unresolved=v.count(UNRESOLVED), total=len(v),
                          failures=[dict(concentration=r["concentration"], policy=r["policy"],
                                         metric=r["metric"],
                                         interval=r["runs"][label][r["statistic"]])
                                    for r in rows if r["runs"][label]["verdict"] == FAIL])
    return out


def supports(record: dict, step: str, extensions=()) -> bool:
    """Whether an equivalence record supports ``step`` as a default: the
    step is shown equivalent on no fewer than :data:`RESOLVED` of the rows
    and not shown equivalent on none (the others are those the control does
    not resolve, where these fields cannot tell a rounding error from the
    margin). A row the record leaves short counts as equivalent where one
    of ``extensions`` (records of the same environment that sail such rows
    on more fields, judged with a stricter interval) shows the step
    equivalent on it."""
    stats = (record.get("data") or {}).get("statistics") or {}
    rows = stats.get("rows") or []
    if not rows or any(step not in r["runs"] for r in rows):
        return False
    env = record["data"]["settings"].get("env", ENV_ID)
    settled = {(r["concentration"], r["policy"], r["metric"])
               for e in extensions if e["data"]["settings"].get("env", ENV_ID) == env
               and e["data"]["settings"].get("statistic") == "trimmed"
               and e["data"].get("confidence", CONFIDENCE) > record["data"].get(
                   "confidence", CONFIDENCE)
               for r in (e["data"].get("statistics") or {}).get("rows", [])
               if step in r["runs"] and r["runs"][step]["verdict"] == PASS}
    verdicts_ = [PASS if (r["concentration"], r["policy"], r["metric"]) in settled
                 else r["runs"][step]["verdict"] for r in rows]
    return FAIL not in verdicts_ and verdicts_.count(PASS) >= RESOLVED * len(rows)


def conclusions(fields: list[dict], st: dict) -> dict:
    """The leaderboard's conclusions under each step: per step, whether route
    choice pays at each concentration (:func:`agents.leaderboard.route_choice_pays`,
    the best planner and its ratios), and, over all concentrations together,
    each policy's impulse per metre over the straight line's (ratio of
    means), the order of the policies by it, and the paired difference of
    the planners' impulse per metre (the second of
    :data:`POLICIES` present minus the third) with its standard error.
    Empty unless the straight line and a planner ran."""
    from agents.leaderboard import pooled_comparison, route_choice_pays, summarise_board
    from agents.rollouts import compare

    planners = [p for p in st["policies"] if p != "straight"]
    if "straight" not in st["policies"] or not planners:
        return {}
    out = {}
    for label in (REFERENCE, *st["variants"], CONTROL):
        board = {f"{a:g}": {name: [dict(final={k: r[k] for k in KEPT}, ret=r["ret"],
                                        length=r["length"])
                                   for r in _runs(fields, a, name, label)]
                            for name in st["policies"]}
                 for a in st["concentrations"]}
        summary = summarise_board(board)
        pays = route_choice_pays(summary, planners)
        pooled = pooled_comparison(board)
        ratios = {"straight": 1.0, **{p: pooled[p]["ipm_ratio_of_means"] for p in planners}}
        entry = dict(route_choice={a: dict(best=b, ratio=r, path=pth, pays=ok)
                                   for a, (b, r, pth, ok) in pays.items()},
                     pooled_ratio=ratios, order=sorted(ratios, key=ratios.get))
        if len(planners) >= 2:
            first, second = planners[0], planners[1]
            mine = [e for pol in board.values() for e in pol[second]]
            theirs = [e for pol in board.values() for e in pol[first]]
            entry["planners"] = dict(compare(mine, theirs, "impulse_per_metre"),
                                     pair=[second, first])
        out[label] = entry
    return out


def rate_rows(fields: list[dict], st: dict) -> list[dict]:
    """Per step and concentration, over the straight-line episodes (or the
    first policy's): env steps over wall time, whole transits (reset
    included); and over all concentrations together."""
    name = "straight" if "straight" in st["policies"] else st["policies"][0]
    rows = []
    for label in (REFERENCE, *st["variants"]):
        per = {}
        for a in st["concentrations"]:
            runs = _runs(fields, a, name, label)
            per[f"{a:g}"] = sum(r["length"] for r in runs) / sum(r["wall"] for r in runs)
        runs = [r for a in st["concentrations"] for r in _runs(fields, a, name, label)]
        engaged = [r["tally"][2] / r["tally"][3] for r in runs if r["tally"] and r["tally"][3]]
        rows.append(dict(step=label, policy=name, per_concentration=per,
                         pooled=sum(r["length"] for r in runs) / sum(r["wall"] for r in runs),
                         engaged_per_substep=float(np.mean(engaged)) if engaged else None,
                         floes=float(np.mean([r["floes"] for r in runs]))))
    return rows


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
    envs = {v: make_checked_env(st["env"], env_kwargs(None, v, st["small"], st["env"]),
                                seed=seed)
            for v in (REFERENCE, *st["variants"])}
    try:
        for env in envs.values():
            _timed_episode(env, seed, late_after)                        # untimed
        runs = [lambda env=env: _timed_episode(env, seed, late_after) for env in envs.values()]
        rounds = harness.interleaved_rounds(runs, st["rounds"])
        u = envs[REFERENCE].unwrapped
        concentration = float(u.episode["concentration"])
        floes = int(u.sim.n_floes)
    finally:
        for env in envs.values():
            env.close()
    return dict(env=st["env"], seed=seed, late_after=late_after, concentration=concentration,
                drawn="concentration" not in env_kwargs(None, REFERENCE, st["small"], st["env"]),
                floes=floes, rounds=dict(zip(envs, rounds)))


def summarise_speed(speed: dict) -> dict:
    """Per step the best round and the slowest of the rate and of the late
    ms per env step, and each step's gain over the reference (best over
    best)."""
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
                         substeps=tally[3] if tally else None)
    e = out[REFERENCE]
    out["gain"] = {step: dict(rate=s["rate"] / e["rate"],
                              late=(e["late_ms"] / s["late_ms"]
                                    if e["late_ms"] and s["late_ms"] else None))
                   for step, s in list(out.items()) if step != REFERENCE}
    return out


# ---------------------------------------------------------------------------
# the record
# ---------------------------------------------------------------------------

def _spread(best: float, slowest: float, higher_is_better: bool) -> str:
    if best is None or slowest is None:
        return "–"
    worse = 1 - slowest / best if higher_is_better else slowest / best - 1
    return f"{'−' if higher_is_better else '+'}{100 * worse:.0f} %"


def _interval(iv) -> str:
    """A relative interval (centre, lower, upper) as percentages."""
    if iv is None or not all(math.isfinite(v) for v in iv):
        return "–"
    return f"{100 * iv[0]:+.1f} % [{100 * iv[1]:+.1f}, {100 * iv[2]:+.1f}]"


def speed_table(speed: dict, summary: dict, rounds: int) -> dict:
    """Env steps/s and late ms per env step under each step, and the floes
    each step integrates."""
    rows = []
    for step in speed["rounds"]:
        s = summary[step]
        g = summary["gain"].get(step)
        rows.append([step, s["rate"], _spread(s["rate"], s["slowest_rate"], True),
                     "–" if g is None else f"{g['rate']:.2f}×",
                     s["late_ms"], _spread(s["late_ms"], s["slowest_late_ms"], False),
                     s["awake_mean"], s["engaged_per_step"]])
    first = summary[REFERENCE]
    return harness.table(
        f"Speed on one thread: one zero-action episode of `{speed['env']}`, seed "
        f"{speed['seed']}, A = "
        f"{speed['concentration']:.3f} "
        f"({'as the environment draws it' if speed['drawn'] else 'set by the instance'}), "
        f"{speed['floes']} floes (best of {rounds} round{'s' * (rounds != 1)})",
        ["step", "env steps/s (whole episode)", "slowest round", f"over {REFERENCE}",
         f"ms per env step after step {speed['late_after']}", "slowest round",
         "floes awake or engaged at the end of an env step (mean)",
         "engaged floe-steps per substep"], rows,
        f"Env steps/s: the {first['steps']} env steps of the episode over their own wall time, "
        f"the reset left out; "
        + (f"the late figure is the mean over its last {first['late_steps']} steps"
           if first["late_steps"] else
           f"the episode ends before step {speed['late_after']}, so there is no late figure")
        + ". Slowest round: how much worse than the best the slowest round was. Floes "
        "awake (exact step: those not at rest, `sim.n_awake`) or engaged (fast steps: those "
        "of the last window that take the contact step) at the end of each env step, "
        "averaged over the episode; engaged floe-steps per substep from the fast steps' "
        "`sim.free_tally`, over the whole episode.")


def summary_table(rows: list[dict], st: dict, tally: dict) -> dict:
    """Per candidate and the control: the rows that pass, fail and are
    unresolved, and the failures."""
    body = []
    for label in (*st["variants"], CONTROL):
        v = tally[label]
        failures = "; ".join(
            f"A = {f['concentration']:g}, {f['policy']}, {_label(f['metric'])}: "
            f"{_interval(f['interval'])}" for f in v["failures"]) or "–"
        body.append([label, f"{v['passed']} of {v['total']}", v["failed"], v["unresolved"],
                     failures])
    statistics = [r["statistic"] for r in rows]
    return harness.table(
        f"The equivalence test on `{st['env']}`: {st['seeds']} fields per concentration and "
        f"policy, margin ±{100 * MARGIN:g} % of the exact mean, "
        f"{100 * st.get('confidence', CONFIDENCE):g} % "
        f"intervals",
        ["step", "rows equivalent", "rows not shown equivalent", "rows unresolved",
         "not shown equivalent: interval of (step − exact) / exact mean"], body,
        f"A row (concentration, policy, metric) is equivalent when the "
        f"{100 * st.get('confidence', CONFIDENCE):g} % "
        f"interval of the centre of the per-field differences lies within ±{100 * MARGIN:g} % "
        f"of the exact step's mean. "
        + (f"The centre is the {100 * TRIM:g} %-trimmed mean on every row; "
           if st.get("statistic", "trimmed") == "trimmed" else
           f"The centre is the mean on {statistics.count('mean')} rows and the "
           f"{100 * TRIM:g} %-trimmed mean on {statistics.count('trimmed')}, as the control "
           f"decides (the mean where the control's interval of the mean lies within the "
           f"margin); ")
        + f"{statistics.count(None)} rows are not resolved for the control. The control is "
          f"the exact step with every floe's velocity nudged by {NUDGE:g} m/s at reset: what "
          f"chaos alone does to the same fields.")


def _label(key: str) -> str:
    return next(label for k, label, *_ in METRICS if k == key)


def equivalence_table(rows: list[dict], st: dict) -> dict:
    """Every row: the exact mean, the statistic, and the interval and
    verdict of the control and of each candidate."""
    labels = {key: (f"{label} [{unit}]" if unit else label, scale)
              for key, label, scale, unit in METRICS}
    fallback = "trimmed" if st.get("statistic", "trimmed") == "trimmed" else "mean"
    body = []
    for r in rows:
        label, scale = labels[r["metric"]]
        stat = r["statistic"]
        cells = [r["concentration"], r["policy"], label, r["reference"] / scale,
                 {"mean": "mean", "trimmed": "trimmed mean", None: "–"}[stat]]
        for step in (CONTROL, *st["variants"]):
            o = r["runs"][step]
            shown = o[stat] if stat else o[fallback]
            verdict = o["verdict"] if o["verdict"] != PASS else ""
            beside = ("" if (stat or fallback) == "mean" or not math.isfinite(o["mean"][0]) else
                      f"; mean {100 * o['mean'][0]:+.1f} % [{100 * o['mean'][1]:+.1f}, "
                      f"{100 * o['mean'][2]:+.1f}]")
            cells.append(f"{_interval(shown)} {verdict}".strip() + beside)
        body.append(cells)
    return harness.table(
        "Every row: (step − exact) / exact mean, the centre and its interval",
        ["A", "policy", "metric", "mean, exact", "statistic", CONTROL, *st["variants"]], body,
        f"Each cell: the centre of the per-field differences relative to the exact mean and "
        f"its {100 * st.get('confidence', CONFIDENCE):g} % interval (the row's statistic), then, "
        f"where that is the "
        f"trimmed mean, the mean and its interval; a cell is marked when its interval is not "
        f"within ±{100 * MARGIN:g} % (fail), or when the control's is not (unresolved; the "
        f"cell then shows the {fallback}).")


def conclusions_table(concl: dict, st: dict) -> dict:
    """Route choice and the policies' order under each step."""
    body = []
    for label, c in concl.items():
        pays = ", ".join(f"{a}: {'yes' if v['pays'] else 'no'} ({v['best']} {v['ratio']:.3f})"
                         for a, v in c["route_choice"].items())
        order = " < ".join(f"{p} ({c['pooled_ratio'][p]:.3f})" for p in c["order"])
        pl = c.get("planners")
        planners = "–" if pl is None else (
            f"{pl['pair'][0]} − {pl['pair'][1]}: {pl['diff'] / 1e3:+.2f} ± {pl['sem'] / 1e3:.2f}")
        body.append([label, pays, order, planners])
    return harness.table(
        "The leaderboard's conclusions under each step",
        ["step", "route choice pays (best planner, impulse per metre / straight)",
         "order by impulse per metre, all A (ratio of means to straight)",
         "planners' paired difference in impulse per metre [kN s/m] (mean ± SE)"], body,
        "Route choice pays at a concentration when the best planner meets at most 0.7 "
        "times the straight line's impulse per metre (ratio of means) sailing at most 10 % "
        f"further, as on the leaderboard. The order pools the {len(st['concentrations'])} "
        f"concentrations' {st['seeds']} fields each.")


def policy_words(name: str) -> str:
    """How the tables name a policy's episodes."""
    return "the straight line" if name == "straight" else f"the {name} policy"


def rate_table(rates: list[dict], st: dict) -> dict:
    """Sustained env steps/s of each step per concentration."""
    concentrations = [f"{a:g}" for a in st["concentrations"]]
    ref = next(r for r in rates if r["step"] == REFERENCE)
    body = [[r["step"], *[r["per_concentration"][a] for a in concentrations], r["pooled"],
             f"{r['pooled'] / ref['pooled']:.2f}×", r["engaged_per_substep"]] for r in rates]
    return harness.table(
        f"Sustained rates: env steps/s over whole transits ({policy_words(rates[0]['policy'])})",
        ["step", *[f"A = {a}" for a in concentrations], "all A", f"over {REFERENCE}",
         "engaged floe-steps per substep"], body,
        f"The env steps of the {st['seeds']} episodes of {policy_words(rates[0]['policy'])} "
        f"per concentration over their wall time, reset included, each in a worker process on "
        f"one Numba thread, {st['workers']} workers side by side on the machine; all A: the "
        f"episodes of every concentration together.")


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


def parse_policies(text: str, env_id: str = ENV_ID) -> tuple[str, ...]:
    """The policies of ``--policies``: baselines of the environment
    (:func:`agents.baselines.baseline_names`), in the order given.

    Raises
    ------
    ValueError
        If one is unknown, or none is given.
    """
    from agents.baselines import baseline_names

    valid = baseline_names(env_id)
    names = tuple(dict.fromkeys(n.strip() for n in str(text).split(",") if n.strip()))
    unknown = [n for n in names if n not in valid]
    if unknown or not names:
        raise ValueError(f"unknown policy(s) {', '.join(unknown) or '(none)'}; known: "
                         f"{', '.join(valid)}")
    return names


def record_title(st: dict) -> str:
    """The title of a record of the settings ``st``: :data:`TITLE`, with the
    environment when it is not :data:`ENV_ID` and the statistic when the
    control chose it (``--statistic control``, the pilot's rule)."""
    parts = [] if st["env"] == ENV_ID else [st["env"].split("/")[1]]
    if st.get("statistic") == "control":
        parts.append("the pilot, its statistic chosen by the control")
    if st.get("confidence", CONFIDENCE) != CONFIDENCE:
        parts.append(f"rows sailed again: {', '.join(st['policies'])} at A = "
                     f"{', '.join(f'{a:g}' for a in st['concentrations'])}, {st['seeds']} "
                     f"fields, {100 * st['confidence']:g} % intervals")
    return f"{TITLE} ({'; '.join(parts)})" if parts else TITLE


def record_path(path, env_id: str):
    """Where the record of ``env_id`` goes: ``path`` as given, unless it is
    the suite's own file of a directory (``--docs`` or the default) and the
    environment is not :data:`ENV_ID`, whose record keeps that name; then
    ``<suite>-<name>.json`` beside it."""
    from pathlib import Path

    path = Path(path)
    if env_id == ENV_ID or path.name != f"{SUITE}.json":
        return path
    return path.with_name(f"{SUITE}-{env_id.split('/')[1]}.json")


def main(argv=None, prog: str | None = None) -> int:
    p = harness.suite_parser(SUITE, TITLE + ": " + DESCRIPTION, prog)
    p.add_argument("--parts", default=None,
                   help="what to measure, comma-separated: " + ", ".join(PARTS)
                        + " (default: both)")
    p.add_argument("--env", default=ENV_ID, choices=list(ENVS),
                   help=f"the ship environment (default {ENV_ID}); the record of another one "
                        f"is written beside this one's, as {SUITE}-<name>.json")
    p.add_argument("--seeds", type=int, default=None,
                   help=f"fields per concentration and policy (default {DEFAULTS['seeds']})")
    p.add_argument("--concentrations", default=None,
                   help="ice concentrations, comma-separated (default: the environment's, "
                        + "; ".join(f"{e.split('/')[1]}: {','.join(f'{a:g}' for a in v['concentrations'])}"
                                    for e, v in ENVS.items()) + "; --quick: the first)")
    p.add_argument("--policies", default=None,
                   help="baselines, comma-separated (default: the environment's, "
                        + "; ".join(f"{e.split('/')[1]}: {','.join(v['policies'])}"
                                    for e, v in ENVS.items()) + "; --quick: the first two)")
    p.add_argument("--variants", default=None,
                   help="steps compared with the exact one, comma-separated: "
                        + ", ".join(CANDIDATES) + " (default: all)")
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
    p.add_argument("--fields", default=None, metavar="PATH",
                   help="also write every field's runs to this JSON file (the record keeps "
                        "the summaries)")
    p.add_argument("--runs", default=None, metavar="PATH", nargs="+",
                   help="take the fields' runs from these JSON files (written by --fields) "
                        "instead of sailing them, and compute the statistics of them")
    p.add_argument("--confidence", type=float, default=CONFIDENCE,
                   help=f"the confidence of the intervals (default {CONFIDENCE:g}; the two "
                        f"one-sided tests are each at half of one minus it)")
    p.add_argument("--statistic", default="trimmed", choices=STATISTICS,
                   help="the centre of the differences: the 20 %%-trimmed mean on every row "
                        "(trimmed, the default), or the mean where the control resolves the "
                        "margin with it and the trimmed mean elsewhere (control)")
    args, argv = harness.parse(p, argv)
    st = harness.settings(args, DEFAULTS, QUICK, ("seeds", "seed", "workers", "speed_seed",
                                                  "rounds", "late_after"))
    if st["seeds"] < 5:
        p.error(f"--seeds must be at least 5 (the trimmed mean's interval), got {st['seeds']}")
    if min(st["workers"], st["rounds"]) < 1 or st["late_after"] < 0:
        p.error("--workers and --rounds must be at least 1, --late-after at least 0")
    st["env"] = args.env
    own = ENVS[args.env]
    st["concentrations"] = own["concentrations"][:1] if args.quick else own["concentrations"]
    st["policies"] = own["policies"][:2] if args.quick else own["policies"]
    args.json = record_path(args.json, args.env)
    try:
        parts = parse_parts(args.parts)
        if args.concentrations is not None:
            st["concentrations"] = parse_concentrations(args.concentrations)
        if args.policies is not None:
            st["policies"] = parse_policies(args.policies, args.env)
        if args.variants is not None:
            st["variants"] = tuple(harness.pick_names(args.variants, CANDIDATES, "variant"))
    except ValueError as exc:
        p.error(str(exc))

    t0 = time.perf_counter()
    tables, data = [], dict(parts=parts, settings=st, quick=args.quick, margin=MARGIN,
                            confidence=args.confidence, trim=TRIM, nudge=NUDGE)
    if "speed" in parts:
        if not args.quiet:
            print("speed: one episode per step and round, in a fresh process ...", flush=True)
        speed = harness.spawn_call(speed_child, st, threads=1)
        summary = summarise_speed(speed)
        data["speed"] = dict(speed, summary=summary)
        tables.append(speed_table(speed, summary, st["rounds"]))
        if not args.quiet:
            print("  env steps/s: " + ", ".join(f"{k} {v['rate']:.3g}" for k, v in summary.items()
                                                if k != "gain"), flush=True)
    st["statistic"] = args.statistic
    if not 0.5 < args.confidence < 1.0:
        p.error(f"--confidence must lie in (0.5, 1), got {args.confidence:g}")
    st["confidence"] = args.confidence
    if "statistics" in parts:
        try:
            fields = read_runs(args.runs, st) if args.runs else run_statistics(st, args.quiet)
        except (OSError, ValueError) as exc:
            p.error(str(exc))
        if args.fields:
            with open(args.fields, "w", encoding="utf-8") as fh:
                json.dump(fields, fh)
        rows = equivalence_rows(fields, st)
        tally = verdicts(rows, (*st["variants"], CONTROL))
        concl = conclusions(fields, st)
        rates = rate_rows(fields, st)
        data["statistics"] = dict(rows=rows, verdicts=tally, conclusions=concl, rates=rates)
        tables.append(summary_table(rows, st, tally))
        tables.append(rate_table(rates, st))
        if concl:
            tables.append(conclusions_table(concl, st))
        tables.append(equivalence_table(rows, st))
    title = record_title(st)
    description = (PILOT_DESCRIPTION if st["statistic"] == "control" else
                   EXTENSION_DESCRIPTION if st["confidence"] != CONFIDENCE else DESCRIPTION)
    record = harness.make_record(
        SUITE, title, description, harness.command_line(SUITE, argv), tables, data,
        time.perf_counter() - t0, machine=harness.machine_info(1))
    harness.finish(args, record)
    return 0


if __name__ == "__main__":
    sys.exit(main())
