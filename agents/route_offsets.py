"""A residual taught by rollouts: the costmap lattice's route, moved
sideways by an offset a classifier chooses from the ship's costmap.

The rollout planner (:class:`agents.planners.RolloutPlanner`) gains over the
lattice by trying the lattice's route moved sideways by a few metres, in
rollouts of the episode from a snapshot, and keeping the best. A learner
that imitates it decision for decision must place its route to well under
a metre, which the waypoint students do not (the documentation's
navigation-learner page, "What a student of the rollout planner could
reach"). Here the learner does not place the route: the costmap lattice
places it, and the learner only chooses among the same few offsets,
0 among them. A choice of 0 sails the costmap lattice exactly, so a
learner that cannot tell where to leave the route costs nothing where it
keeps it.

* **The decision** (every ``interval`` = 5 steps, the lattice's replan):
  a choice c of :data:`OFFSETS`; the costmap lattice's waypoints w₀
  (:class:`agents.waypoints.LatticeWaypoints` with teacher
  ``"costmap-lattice"``, 30 and 60 m ahead) are each moved across the
  channel by ``OFFSETS[c]`` metres, and the ship follows them by pure
  pursuit (:class:`agents.waypoints.WaypointFollower`).
* **The teacher**, :class:`RolloutOffsets` (``cm-rollout``; privileged: it
  steps copies of the episode): from a snapshot, each offset's waypoints
  are sailed until the next decision and the costmap lattice on after,
  ``rollout_steps`` steps in all (30: 60 s); the best return is kept when
  it beats the unmoved route's by more than ``margin`` (1), else 0. It is
  the rollout planner of the board's ``rollout-margin-1`` with the costmap
  lattice for its base policy.
* **The learner**, :class:`OffsetStudent` (sensor-only): an SB3 policy
  with a ``Discrete(len(OFFSETS))`` action on the decision's observation
  (:func:`agents.waypoints.decision_observation`: the costmap and the
  ship's pose), the waypoint students' network
  (:func:`agents.waypoints.make_student`); it plays its most likely
  offset.
* **Training** (:func:`train_offsets`): DAgger at the decisions as for
  the waypoint students (round 0: the teacher's episodes; round r: the
  teacher's choice played with probability β^r, the learner's otherwise;
  the teacher labels every decision), fitted by cross-entropy on all
  labels so far and their mirror images (the offsets reversed).

Train, then play on the leaderboard's fields::

    python -m agents.route_offsets train --seed 1 --out runs/offsets/seed_1
    python -m agents.leaderboard --env-kwargs costmap_ahead=500 --out runs/board \\
        --policies "cm-rollout=agents.route_offsets:RolloutOffsets,\\
    offsets=agents.route_offsets:OffsetStudent?run=runs/offsets/seed_1"

A run holds ``student.zip``, ``offsets.json`` (the settings, each round's
decisions, the share of them the teacher moved, the mean return of its
episodes and the fit) and ``labels.npz`` (:data:`LABELS`: every labelled
decision, with each offset's rollout return, for fitting other learners
on them without the rollouts' cost).
"""
from __future__ import annotations

import argparse
import json
import shlex
import sys
import time
from pathlib import Path

import numpy as np

from .leaderboard import DEFAULT_ENV
from .waypoint_follower import (OFFSETS_RECORD, STUDENT, LatticeWaypoints, decision_observation,
                                gather_records, load_student, rollout_decision, sail_fields,
                                student_decision, write_gathered)

__all__ = ["OFFSETS", "KEEP", "LABELS", "OffsetChooser", "RolloutOffsets", "OffsetStudent", "train_offsets",
           "OFFSET_DEFAULTS", "FIT_SETTINGS", "fit_offsets", "load_labels", "choices_of",
           "gains_of", "refit", "crossfit", "held_out", "report", "main"]

#: the offsets [m] a decision chooses among (the rollout planner's
#: ``rollout-margin-1`` search, and 0), sorted so that choice c mirrors into
#: ``len(OFFSETS) - 1 - c``
OFFSETS = (-12.0, -7.0, -3.0, 0.0, 3.0, 7.0, 12.0)
#: the choice that keeps the costmap lattice's own waypoints
KEEP = OFFSETS.index(0.0)
#: the labelled decisions of a run, in its directory: ``costmap`` and
#: ``vector`` (what the learner saw), ``labels`` (the teacher's choices),
#: ``returns`` (every offset's rollout return) and ``round``, one row a decision
LABELS = "labels.npz"


class OffsetChooser(LatticeWaypoints):
    """The costmap lattice's waypoints moved across the channel by the
    offset of a choice (:meth:`choose`, for a subclass to give). Sensor-only
    as far as the choice is.

    Attributes
    ----------
    choices : list of int
        Each decision's choice of :data:`OFFSETS`, in the episode's order.
    """

    def __init__(self, env, seed: int = 0, **kwargs):
        if "teacher" in kwargs:
            raise ValueError("an offset chooser moves the costmap lattice's route; it takes "
                             "no teacher")
        if kwargs.get("form", "waypoints") != "waypoints":
            raise ValueError(f"an offset moves waypoints (form 'waypoints'), got form "
                             f"{kwargs['form']!r}")
        super().__init__(env, seed, teacher="costmap-lattice", **kwargs)
        self.choices: list[int] = []

    def reset(self, seed: int | None = None) -> None:
        super().reset(seed)
        self.choices = []

    def moved(self, base: np.ndarray, choice: int) -> np.ndarray:
        """The decision of waypoints ``base`` (w) moved by ``OFFSETS[choice]``
        metres across the channel, clipped to [−1, 1]."""
        return np.clip(base + OFFSETS[choice] / (self.max_slope * self.distances), -1.0, 1.0)

    def choose(self, obs, base: np.ndarray) -> int:
        """The choice of :data:`OFFSETS` for the episode now (``base``: the
        costmap lattice's decision, clipped)."""
        raise NotImplementedError

    def decide(self, obs):
        base = np.clip(self.label(), -1.0, 1.0)
        choice = int(self.choose(obs, base))
        if not 0 <= choice < len(OFFSETS):
            raise ValueError(f"{type(self).__name__} chose {choice!r}, not a choice "
                             f"0-{len(OFFSETS) - 1} of OFFSETS")
        self.choices.append(choice)
        return self.moved(base, choice)


class RolloutOffsets(OffsetChooser):
    """The teacher (``cm-rollout``; privileged): the offset whose rollout of
    the episode earns most (see the module's text).

    Parameters
    ----------
    env, seed : as :class:`agents.waypoints.LatticeWaypoints`
    rollout_steps : int
        Steps of each rollout: the decision's ``interval``, then the costmap
        lattice (at least ``interval``).
    margin : float
        Keep the costmap lattice's own waypoints unless an offset's rollout
        return beats theirs by more than this (reward, >= 0).
    **kwargs : the follower's settings

    Attributes
    ----------
    returns : list of tuple
        Each decision's rollout returns, one per offset.
    """

    reads_environment = "its costmap, and steps copies of the episode forward"

    def __init__(self, env, seed: int = 0, *, rollout_steps: int = 30, margin: float = 1.0,
                 **kwargs):
        super().__init__(env, seed, **kwargs)
        if not hasattr(self.unwrapped, "snapshot"):
            raise ValueError(f"RolloutOffsets needs an environment with snapshot and restore, "
                             f"got {type(self.unwrapped).__name__}")
        if isinstance(rollout_steps, bool) or int(rollout_steps) != rollout_steps \
                or rollout_steps < self.interval:
            raise ValueError(f"rollout_steps must be an integer >= interval ({self.interval}), "
                             f"got {rollout_steps!r}")
        if isinstance(margin, bool) or not (np.isfinite(float(margin)) and margin >= 0):
            raise ValueError(f"margin must be a number >= 0, got {margin!r}")
        self.rollout_steps, self.margin = int(rollout_steps), float(margin)
        self.returns: list[tuple[float, ...]] = []

    def reset(self, seed: int | None = None) -> None:
        super().reset(seed)
        self.returns = []

    def choose(self, obs, base):
        t0 = time.perf_counter()
        u = self.unwrapped
        snap = u.snapshot()
        returns = []
        for choice in range(len(OFFSETS)):
            # restore before each rollout: a restore puts copies in the episode, so the
            # rollouts step those and leave alone the objects this chooser holds
            u.restore(snap)
            returns.append(self._rollout(obs, self.moved(base, choice)))
        u.restore(snap)
        self.returns.append(tuple(returns))
        best = int(np.argmax(returns))
        self.decision_times[-1] += time.perf_counter() - t0
        return best if returns[best] - returns[KEEP] > self.margin else KEEP

    def _rollout(self, obs, w) -> float:
        """The summed reward of ``rollout_steps`` steps of the episode as it
        is now: decision ``w`` for ``interval`` steps, then the costmap
        lattice (:func:`agents.waypoint_follower.rollout_decision`)."""
        return rollout_decision(self.env, obs, w, self.rollout_steps, points=self.points,
                                distance=self.distance, interval=self.interval)


class OffsetStudent(OffsetChooser):
    """The learner (sensor-only): the most likely offset of the policy of
    ``run`` (a run of :func:`train_offsets`) on the costmap and the ship's
    pose."""

    reads_environment = "its costmap and its own pose"

    def __init__(self, env, seed: int = 0, *, run: str, **kwargs):
        if not (Path(run) / OFFSETS_RECORD).is_file():
            raise ValueError(f"{run!r} holds no offset learner ({OFFSETS_RECORD} is missing; "
                             f"train one with python -m agents.route_offsets train --out {run})")
        self.policy = load_student(run, env)
        super().__init__(env, seed, **kwargs)

    def choose(self, obs, base):
        return student_decision(self.policy, decision_observation(self.env))


class _Labeller(RolloutOffsets):
    """The teacher labels every decision; its choice is played with
    probability ``beta``, the learner's (``policy``; None: never) otherwise."""

    def __init__(self, env, seed, policy, beta, coin, **kwargs):
        super().__init__(env, seed, **kwargs)
        self.policy, self.beta, self.coin = policy, float(beta), coin
        self.seen: list[dict] = []
        self.labels: list[int] = []
        #: every labelled decision's rollout returns, of all episodes (``returns``
        #: holds the episode's own only)
        self.all_returns: list[tuple[float, ...]] = []

    def choose(self, obs, base):
        seen = decision_observation(self.env)
        wanted = super().choose(obs, base)
        self.seen.append(seen)
        self.labels.append(wanted)
        self.all_returns.append(self.returns[-1])
        if self.policy is None or self.coin.random() < self.beta:
            return wanted
        return student_decision(self.policy, seen)


#: the settings of :func:`train_offsets` (a 500 m costmap, as the costmap
#: lattice's best students were trained on)
OFFSET_DEFAULTS = dict(env_id=DEFAULT_ENV,
                       env_kwargs={"costmap_ahead": 500.0}, episodes=12, rounds=1, beta=0.5,
                       epochs=20, batch_size=128, learning_rate=3e-4, cnn_dim=128,
                       rollout_steps=30, margin=1.0, field_seed=100_000, oversample=1)
#: the settings of a fit (:func:`fit_offsets`), which :func:`refit` and
#: :func:`crossfit` take
FIT_SETTINGS = ("epochs", "batch_size", "learning_rate", "cnn_dim", "oversample")


def _check_fit(s: dict) -> None:
    for name in ("epochs", "batch_size", "cnn_dim", "oversample"):
        if isinstance(s[name], bool) or int(s[name]) != s[name] or s[name] < 1:
            raise ValueError(f"{name} must be an integer >= 1, got {s[name]!r}")


def fit_offsets(env, seen: dict, labels: np.ndarray, seed: int, fit_seed: int, s: dict):
    """A new learner's network (seeded ``seed``) fitted by cross-entropy on
    the decisions ``seen`` and the teacher's ``labels``, with their mirror
    images; each moved decision (a label other than :data:`KEEP`) is
    repeated ``oversample`` times, so that a fit of rare moves does not
    settle on keeping the route everywhere. Returns (policy, the fit's
    record)."""
    from .pretrain import fit_policy
    from .waypoints import make_student, with_mirror

    rows = np.concatenate([np.arange(len(labels)),
                           np.repeat(np.flatnonzero(labels != KEEP), int(s["oversample"]) - 1)])
    rows.sort()
    chosen = {k: v[rows] for k, v in seen.items()} if len(rows) != len(labels) else seen
    data, _ = with_mirror(chosen, np.zeros((len(rows), 1)))
    targets = np.concatenate([labels[rows], len(OFFSETS) - 1 - labels[rows]])
    policy = make_student(env, choices=len(OFFSETS), cnn_dim=s["cnn_dim"],
                          learning_rate=s["learning_rate"], seed=seed)
    fit = fit_policy(policy, data, targets, None, epochs=s["epochs"],
                     batch_size=s["batch_size"], learning_rate=s["learning_rate"],
                     seed=fit_seed)
    return policy, fit


def load_labels(run) -> dict:
    """The labelled decisions of the run directory ``run`` (:data:`LABELS`);
    without ``returns`` where the file holds none for some decisions."""
    path = Path(run) / LABELS
    if not path.is_file():
        raise FileNotFoundError(f"{run}: no {LABELS} (not a run of python -m agents.route_offsets "
                                f"train)")
    with np.load(path) as saved:
        labels = {k: saved[k] for k in saved.files}
    if len(labels.get("returns", ())) != len(labels["labels"]):
        labels.pop("returns", None)   # not one row a decision: not kept whole
    return labels


def choices_of(policy, seen: dict, batch: int = 256) -> np.ndarray:
    """The most likely choice of ``policy`` on each decision of ``seen``."""
    n = len(seen["vector"])
    return np.concatenate([np.asarray(policy.predict(
        {k: v[i:i + batch] for k, v in seen.items()}, deterministic=True)[0]).reshape(-1)
        for i in range(0, n, batch)]).astype(np.int64)


def gains_of(returns: np.ndarray, made: np.ndarray) -> np.ndarray:
    """Each decision's rollout return of choice ``made`` minus that of
    keeping the route: what the choice earned over the costmap lattice in
    the rollout (a window of ``rollout_steps``)."""
    n = np.arange(len(made))
    return returns[n, made] - returns[n, KEEP]


def refit(run, out, seed: int | None = None, **settings) -> dict:
    """A learner fitted again on the labelled decisions of ``run``, with
    the fit's ``settings`` (:data:`FIT_SETTINGS`) changed, into ``out`` (a
    run directory :class:`OffsetStudent` plays, without ``labels.npz``):
    no rollouts. ``seed``: the network's (default the run's)."""
    import gymnasium as gym

    import iceenvs  # noqa: F401  (registers the ids)

    unknown = sorted(set(settings) - set(FIT_SETTINGS))
    if unknown:
        raise ValueError(f"unknown settings {unknown}; valid: {', '.join(FIT_SETTINGS)}")
    record = json.loads((Path(run) / OFFSETS_RECORD).read_text())
    saved = load_labels(run)
    s = {**OFFSET_DEFAULTS, **record["settings"], **settings}
    _check_fit(s)
    seed = int(s["seed"] if seed is None else seed)
    env = gym.make(s["env_id"], **s["env_kwargs"])
    began = time.perf_counter()
    try:
        policy, fit = fit_offsets(env, {k: saved[k] for k in ("costmap", "vector")},
                                  saved["labels"], seed, seed * 1000 + 999, s)
    finally:
        env.close()
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    policy.save(str(out / STUDENT))
    new = {**record, "settings": {**s, "seed": seed}, "refit_of": Path(run).as_posix(),
           "refit": {**{k: v for k, v in fit.items() if k.startswith("action_")},
                     "seconds": round(time.perf_counter() - began, 1)}}
    (out / OFFSETS_RECORD).write_text(json.dumps(new, indent=2) + "\n")
    return new


def crossfit(runs, out, oversample=(1,), progress: bool = True, **settings) -> dict:
    """Whether the teacher's choices can be learned, run by run: for each
    run of ``runs`` and each ``oversample``, a learner is fitted on the
    labelled decisions of the others and chooses on the run's own, fields
    it never saw. What its choices earn is read from the run's saved
    rollouts (:func:`gains_of`): no rollouts are sailed. Writes
    ``out/crossfit.json`` and the table ``out/crossfit.md``; returns the
    record."""
    import gymnasium as gym
    from tqdm.auto import tqdm

    import iceenvs  # noqa: F401  (registers the ids)

    runs = [Path(r) for r in runs]
    if len(runs) < 2:
        raise ValueError("a cross-fit needs at least two runs")
    unknown = sorted(set(settings) - set(FIT_SETTINGS))
    if unknown or "oversample" in settings:
        raise ValueError(f"unknown settings {unknown or ['oversample']}; valid: "
                         f"{', '.join(f for f in FIT_SETTINGS if f != 'oversample')}")
    first = {**OFFSET_DEFAULTS, **json.loads((runs[0] / OFFSETS_RECORD).read_text())["settings"]}
    saved = [load_labels(r) for r in runs]
    env = gym.make(first["env_id"], **first["env_kwargs"])
    rows = []
    try:
        for m in tqdm(oversample, desc="oversample", disable=not progress):
            s = {**first, **settings, "oversample": m}
            _check_fit(s)
            for k, run in enumerate(runs):
                others = [d for j, d in enumerate(saved) if j != k]
                seen = {key: np.concatenate([d[key] for d in others])
                        for key in ("costmap", "vector")}
                policy, _ = fit_offsets(env, seen, np.concatenate([d["labels"] for d in others]),
                                        k + 1, k + 1, s)
                mine = saved[k]
                made = choices_of(policy, {key: mine[key] for key in ("costmap", "vector")})
                wanted = mine["labels"]
                rows.append({"run": run.as_posix(), "oversample": m, **_agreement(made, wanted),
                             **({"teacher_gain": float(np.mean(gains_of(mine["returns"], wanted))),
                                 "gain": float(np.mean(gains_of(mine["returns"], made)))}
                                if "returns" in mine else {"teacher_gain": None, "gain": None})})
    finally:
        env.close()
    lines = ["| held-out run | oversample | decisions | moved by the teacher | moved by the "
             "learner | the learner's moves the teacher's | the teacher's moves made | the "
             "teacher's rollout gain per decision | the learner's |",
             "|---|---|---|---|---|---|---|---|---|"]
    lines += [f"| {r['run']} | {r['oversample']} | {r['decisions']} | {_share(r['teacher_moved'])}"
              f" | {_share(r['moved'])} | {_share(r['moves_right'])} | "
              f"{_share(r['teacher_moves_made'])} | {_number(r['teacher_gain'])} | "
              f"{_number(r['gain'])} |" for r in rows]
    lines.append("")
    record = {"settings": {**{k: first[k] for k in FIT_SETTINGS}, **settings,
                           "oversample": list(oversample)}, "rows": rows}
    write_gathered(out, "crossfit.json", record, "crossfit.md", lines)
    return record


def train_offsets(out, seed: int, progress: bool = True, command: str | None = None,
                  quiet: bool = False, **settings) -> dict:
    """Train an :class:`OffsetStudent` into ``out`` by DAgger from
    :class:`RolloutOffsets` (see the module's text); returns the record
    written to ``out/offsets.json``.

    Round r sails ``episodes`` fields seeded ``field_seed`` + 1000 × seed +
    r × ``episodes`` + k (round 0: the teacher alone), so that each
    training seed sails fields of its own; the learner is fitted from a new
    network seeded by ``seed`` after each round, on every label so far and
    their mirror images."""
    import gymnasium as gym

    import iceenvs  # noqa: F401  (registers the ids)

    from . import observations as obs_rows

    unknown = sorted(set(settings) - set(OFFSET_DEFAULTS))
    if unknown:
        raise ValueError(f"unknown settings {unknown}; valid: {', '.join(OFFSET_DEFAULTS)}")
    s = {**OFFSET_DEFAULTS, **settings}
    _check_fit(s)
    if isinstance(s["episodes"], bool) or int(s["episodes"]) != s["episodes"] \
            or s["episodes"] < 1:
        raise ValueError(f"episodes must be an integer >= 1, got {s['episodes']!r}")
    if isinstance(s["rounds"], bool) or int(s["rounds"]) != s["rounds"] or s["rounds"] < 0:
        raise ValueError(f"rounds must be an integer >= 0, got {s['rounds']!r}")
    if not 0.0 <= s["beta"] <= 1.0:
        raise ValueError(f"beta must lie in [0, 1], got {s['beta']!r}")
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    env = gym.make(s["env_id"], **s["env_kwargs"])
    policy = None
    seen: dict | None = None
    labels, round_of = np.empty(0, dtype=np.int64), np.empty(0, dtype=np.int64)
    rollout_returns = np.empty((0, len(OFFSETS)))
    rounds = []
    began = time.perf_counter()
    try:
        for r in range(s["rounds"] + 1):
            start = time.perf_counter()
            beta = 1.0 if r == 0 else float(s["beta"]) ** r
            driver = _Labeller(env, seed, policy, beta, np.random.default_rng([seed, r]),
                               rollout_steps=s["rollout_steps"], margin=s["margin"])
            first = s["field_seed"] + 1000 * seed + r * s["episodes"]
            returns = sail_fields(env, driver, first, s["episodes"],
                                  f"round {r} (beta {beta:.3g})", progress)
            new = obs_rows.stack(driver.seen)
            seen = new if seen is None else {k: np.concatenate([seen[k], new[k]]) for k in seen}
            wanted = np.asarray(driver.labels, dtype=np.int64)
            labels = np.concatenate([labels, wanted])
            rollout_returns = np.concatenate(
                [rollout_returns, np.asarray(driver.all_returns).reshape(-1, len(OFFSETS))])
            round_of = np.concatenate([round_of, np.full(len(wanted), r)])
            np.savez_compressed(out / LABELS, labels=labels, returns=rollout_returns,
                                round=round_of, **seen)
            del new, driver
            policy, fit = fit_offsets(env, seen, labels, seed, seed * 1000 + r, s)
            rounds.append({"round": r, "beta": beta, "decisions": len(wanted),
                           "moved": float(np.mean(wanted != KEEP)),
                           "mean_return": float(np.mean(returns)),
                           **{k: v for k, v in fit.items() if k.startswith("action_")},
                           "seconds": round(time.perf_counter() - start, 1)})
            if not quiet:
                print(f"round {r} (beta {beta:.3g}): {len(wanted)} decisions, "
                      f"{rounds[-1]['moved']:.0%} moved, mean return {np.mean(returns):.1f}, "
                      f"accuracy {fit['action_accuracy']:.3f}, {rounds[-1]['seconds']:.0f} s",
                      flush=True)
    finally:
        env.close()
    record = {"settings": {**s, "seed": seed, "offsets": list(OFFSETS)}, "rounds": rounds,
              "labels": np.bincount(labels, minlength=len(OFFSETS)).tolist(),
              "seconds": round(time.perf_counter() - began, 1), "command": command}
    policy.save(str(out / STUDENT))
    (out / OFFSETS_RECORD).write_text(json.dumps(record, indent=2) + "\n")
    return record


def held_out(run, episodes: int, seed: int, progress: bool = False) -> dict:
    """The learner of ``run`` sailing ``episodes`` fields seeded ``seed`` +
    k (of its environment's settings), the teacher labelling each of its
    decisions as in training: the decisions, the share the learner moved
    and the teacher would have, the share of the learner's moves that were
    the teacher's choice, the share of the teacher's moves the learner
    made, and the accuracy."""
    import gymnasium as gym

    import iceenvs  # noqa: F401  (registers the ids)

    s = json.loads((Path(run) / OFFSETS_RECORD).read_text())["settings"]
    env = gym.make(s["env_id"], **s["env_kwargs"])
    try:
        policy = load_student(run, env)
        driver = _Labeller(env, 0, policy, 0.0, np.random.default_rng(0),
                           rollout_steps=s["rollout_steps"], margin=s["margin"])
        sail_fields(env, driver, seed, episodes, f"held out {run}", progress)
    finally:
        env.close()
    wanted = np.asarray(driver.labels)
    made = np.asarray(driver.choices)
    return {"episodes": episodes, "seed": seed, **_agreement(made, wanted),
            "accuracy": float(np.mean(made == wanted))}


def _agreement(made: np.ndarray, wanted: np.ndarray) -> dict:
    """How a learner's choices ``made`` agree with the teacher's ``wanted``
    on the same decisions: their number, the share each moved the route,
    the share of the learner's moves that were the teacher's choice and the
    share of the teacher's moves the learner made (None: no move)."""
    moved, taught = made != KEEP, wanted != KEEP
    return {"decisions": len(made), "teacher_moved": float(np.mean(taught)),
            "moved": float(np.mean(moved)),
            "moves_right": float(np.mean(made[moved] == wanted[moved])) if moved.any() else None,
            "teacher_moves_made": float(np.mean(made[taught] == wanted[taught]))
            if taught.any() else None}


def _share(value) -> str:
    return "–" if value is None else f"{value:.1%}"


def _number(value) -> str:
    return "–" if value is None else f"{value:.3f}"


def report(runs, out, held_out_episodes: int = 0, held_out_seed: int = 50_000,
           progress: bool = False) -> dict:
    """Gather the runs' records into ``out/offsets.json``, a table
    ``out/offsets.md`` (a row per run and round) and a figure
    ``out/offsets.png`` (the teacher's labels by offset, run by run); with
    ``held_out_episodes``, each learner also sails that many fields seeded
    ``held_out_seed`` + k under the teacher's labels (:func:`held_out`),
    into ``out/held-out.md`` and each record's ``held_out``. Returns the
    records."""
    records = gather_records(runs, OFFSETS_RECORD, "agents.route_offsets train")
    lines = ["| run | round | β | decisions | moved by the teacher | mean return | accuracy "
             "of the fit | seconds |", "|---|---|---|---|---|---|---|---|"]
    for run, rec in records.items():
        for r in rec["rounds"]:
            lines.append(f"| {run} | {r['round']} | {r['beta']:.3g} | {r['decisions']} | "
                         f"{r['moved']:.1%} | {r['mean_return']:.1f} | "
                         f"{r['action_accuracy']:.3f} | {r['seconds']:.0f} |")
    lines.append("")
    write_gathered(out, OFFSETS_RECORD, records, "offsets.md", lines)
    if held_out_episodes:
        rows = ["| run | decisions | moved by the learner | moved by the teacher | the "
                "learner's moves the teacher's | the teacher's moves made | accuracy |",
                "|---|---|---|---|---|---|---|"]
        for run, rec in records.items():
            h = rec["held_out"] = held_out(run, held_out_episodes, held_out_seed, progress)
            rows.append(f"| {run} | {h['decisions']} | {_share(h['moved'])} | "
                        f"{_share(h['teacher_moved'])} | {_share(h['moves_right'])} | "
                        f"{_share(h['teacher_moves_made'])} | {_share(h['accuracy'])} |")
        rows.append("")
        write_gathered(out, OFFSETS_RECORD, records, "held-out.md", rows)
    _plot(records, Path(out) / "offsets.png")
    return records


def _plot(records: dict, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6.4, 3.2))
    width = 0.8 / len(records)
    for i, (run, rec) in enumerate(records.items()):
        counts = np.asarray(rec["labels"], dtype=float)
        ax.bar(np.arange(len(OFFSETS)) + (i - (len(records) - 1) / 2) * width,
               counts / counts.sum(), width, label=run)
    ax.set_xticks(range(len(OFFSETS)), [f"{o:+g}" if o else "0" for o in OFFSETS])
    ax.set_yscale("log")
    ax.set_xlabel("offset of the costmap lattice's route [m]")
    ax.set_ylabel("share of the teacher's labels")
    ax.legend(fontsize="small")
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m agents.route_offsets",
        description="Train a learner that moves the costmap lattice's route by an offset "
                    "taught by rollouts, or gather the runs' records.")
    sub = parser.add_subparsers(dest="command", required=True)
    train = sub.add_parser("train", help="train an offset learner into --out")
    train.add_argument("--seed", type=int, required=True)
    train.add_argument("--out", required=True)
    for name in ("episodes", "rounds", "epochs", "batch_size", "cnn_dim", "rollout_steps",
                 "field_seed"):
        train.add_argument("--" + name.replace("_", "-"), type=int,
                           help=f"(default {OFFSET_DEFAULTS[name]})")
    for name in ("beta", "learning_rate", "margin"):
        train.add_argument("--" + name.replace("_", "-"), type=float,
                           help=f"(default {OFFSET_DEFAULTS[name]})")
    train.add_argument("--env-kwargs", nargs="*", default=None, metavar="KEY=VALUE",
                       help="the environment's settings (default costmap_ahead=500)")
    train.add_argument("--no-progress", action="store_true")
    ref = sub.add_parser("refit", help="fit a learner again on a run's labelled decisions, "
                                       "into --out (no rollouts)")
    ref.add_argument("--run", required=True)
    ref.add_argument("--out", required=True)
    ref.add_argument("--seed", type=int, help="the network's seed (default the run's)")
    cross = sub.add_parser("crossfit", help="fit on all runs but one and choose on that one's "
                                            "decisions, run by run (no rollouts)")
    cross.add_argument("runs", nargs="+")
    cross.add_argument("--out", required=True)
    cross.add_argument("--oversample", default="1", metavar="M,M,...",
                       help="the oversamplings of moved decisions to compare (default 1)")
    cross.add_argument("--no-progress", action="store_true")
    for p in (ref, cross):
        for name in ("epochs", "batch_size", "cnn_dim"):
            p.add_argument("--" + name.replace("_", "-"), type=int,
                           help="(default the run's)")
        p.add_argument("--learning-rate", type=float, help="(default the run's)")
    ref.add_argument("--oversample", type=int, help="(default the run's)")
    rep = sub.add_parser("report", help="gather run directories' records into --out")
    rep.add_argument("runs", nargs="+")
    rep.add_argument("--out", required=True)
    rep.add_argument("--held-out", type=int, default=0, metavar="N",
                     help="sail each learner on N fields under the teacher's labels (default 0)")
    rep.add_argument("--held-out-seed", type=int, default=50_000,
                     help="the first of those fields' seeds (default 50000)")
    rep.add_argument("--no-progress", action="store_true")
    args = parser.parse_args(argv)
    if args.command == "report":
        if args.held_out < 0:
            parser.error(f"--held-out must be >= 0, got {args.held_out}")
        report(args.runs, args.out, args.held_out, args.held_out_seed,
               progress=not args.no_progress)
        print(f"wrote {args.out}")
        return 0
    if args.command in ("refit", "crossfit"):
        fit = {k: getattr(args, k) for k in ("epochs", "batch_size", "cnn_dim", "learning_rate")
               if getattr(args, k) is not None}
        if args.command == "refit":
            if args.oversample is not None:
                fit["oversample"] = args.oversample
            refit(args.run, args.out, args.seed, **fit)
        else:
            try:
                ms = tuple(int(m) for m in args.oversample.split(","))
            except ValueError:
                parser.error(f"--oversample takes integers, got {args.oversample!r}")
            crossfit(args.runs, args.out, ms, progress=not args.no_progress, **fit)
        print(f"wrote {args.out}")
        return 0
    from .envs import parse_key_values

    given = {k: getattr(args, k) for k in OFFSET_DEFAULTS
             if getattr(args, k, None) is not None}
    if args.env_kwargs is not None:
        given["env_kwargs"] = parse_key_values(args.env_kwargs)
    line = "python -m agents.route_offsets " + shlex.join(
        sys.argv[1:] if argv is None else list(argv))
    train_offsets(args.out, args.seed, progress=not args.no_progress, command=line, **given)
    print(f"wrote {args.out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
