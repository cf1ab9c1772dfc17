"""Waypoint decisions at the planner's pace: a navigation learner that
decides every 10 s where to be 30 and 60 m ahead, taught by the lattice
planner.

The lattice planner (:class:`agents.planners.LatticePlanner`) plans a route
every 5 steps (10 s of model time) and steers along it by pure pursuit in
between. Its action at a step therefore depends on when it last planned,
which a memoryless policy that acts every step cannot know, and a lattice
that replans at every step sails worse than one that commits for 10 s
(the docs' page "A navigation learner that sees what the planner sees"
measures both). Here the learner decides at the lattice's pace and in its
terms:

* **The decision** (every ``interval`` = :data:`DECISION_STEPS` = 5
  steps): ``points`` numbers w_k ∈ [−1, 1] (default 2), the ship's lateral
  position at distances d_k = k × ``distance`` / ``points`` ahead along the
  channel (default 30 and 60 m), as w_k × ``max_slope`` × d_k from where
  it decided (``max_slope`` 0.5, the lattice's steepest: ±15 and ±30 m).
  The route is the straight lines through those waypoints, then on along
  the channel; each waypoint is kept ``edge_margin`` (10 m) inside the
  channel's edges.
* **Between decisions** the ship follows that route by the lattice's own
  pure pursuit (30 m lookahead), with any of the environment's controls.
* **The teacher**, :class:`LatticeWaypoints`, plans the lattice's route at
  each decision and takes its points 30 and 60 m ahead: the ends of the
  lattice's first two stages. Over the 20 m the ship sails until the next
  decision the pursuit's target stays on those two stages, so the teacher
  sails the lattice planner's own episode, step for step (tested). Its
  decision is a function of the ship's pose and the floes at the decision
  alone. With ``--teacher costmap-lattice`` it plans on the costmap the
  student sees, and with ``--teacher-policy`` its routes take a tuned
  planner's settings (:mod:`agents.tuned_lattice`: ``best`` or ``combine``
  prints one), by the episode's concentration where the policy has
  settings for each range of it; the pace and the pursuit stay the
  follower's own.
* **The student**, :class:`WaypointStudent`, decides from what a ship's
  own sensors give (:func:`decision_observation`): the environment's
  costmap (:meth:`iceenvs.ship_env.ShipEnv.costmap`; floes within 300 m
  ahead, 5 m cells, the channel's edges and the goal line) and its own
  pose in the channel (lateral offset, heading, yaw rate). It reads no
  floe itself.
* **Imitation** (:func:`train_student`): DAgger at the decisions (Ross,
  Gordon and Bagnell, AISTATS 2011). Round 0 is behaviour cloning on the
  teacher's episodes; in round r the teacher's waypoints are played with
  probability β^r and the student's otherwise, the teacher labels every
  decision, and the student is fitted again on all labels so far, and on
  their mirror images (:func:`mirrored`: the task is symmetric across the
  ship's track).

Train, then play the student on the leaderboard's fields::

    python -m agents.waypoints train --seed 1 --out runs/waypoints/seed_1
    python -m agents.leaderboard --out runs/board \\
        --policies "lattice,student=agents.waypoints:WaypointStudent?run=runs/waypoints/seed_1"
    python -m agents.waypoints report runs/waypoints/seed_1 ... --out DIR

A run holds ``student.zip`` (the SB3 policy, about 0.5 MB) and
``waypoints.json``: the settings, each round's decisions, the mean return
of its episodes and the fit, and the imitation error on fields of no
round (seeded ``held_out_seed`` + k). With ``--keep-labels`` it also holds
``labels.npz`` (:data:`LABELS`): every labelled decision, of the rounds
and of the held-out fields, with its round and its field, so that
students of other fits can be judged on them without sailing again
(:mod:`agents.imitation_scaling`). ``report`` gathers the runs' records
into one record and a table.
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
from .waypoint_follower import (DECISION_STEPS, FORMS, RECORD, STAGE_CHOICES, STUDENT, TEACHERS,
                                WAYPOINT_DISTANCE, LatticeWaypoints, WaypointFollower,
                                WaypointResidual, WaypointStudent, decision_observation,
                                decision_space, gather_records, sail_fields, student_decision,
                                teacher_route, write_gathered)

# the decision and its follower (agents.waypoint_follower) are named here too
__all__ = ["DECISION_STEPS", "WAYPOINT_DISTANCE", "FORMS", "TEACHERS", "REFITS", "STAGE_CHOICES",
           "STUDENT", "RECORD", "LABELS", "WaypointFollower",
           "LatticeWaypoints", "WaypointStudent", "WaypointResidual", "decision_observation",
           "decision_space",
           "make_student", "mirrored", "with_mirror", "train_student", "fit_text", "report",
           "TRAIN_DEFAULTS", "main"]

#: how a DAgger round fits the student on all labels so far: from its weights
#: after the round before (``warm``), or a new network seeded alike (``fresh``)
REFITS = ("warm", "fresh")

#: a run's labelled decisions (``train --keep-labels``): the arrays
#: ``costmap``, ``vector`` (the decisions' observations), ``labels`` (the
#: teacher's decisions, unclipped), ``round`` and ``field`` (the seed of the
#: decision's field), and the same of the held-out fields prefixed ``held_``
LABELS = "labels.npz"


def make_student(env, *, form: str = "waypoints", points: int = 2, cnn_dim: int = 128,
                 net_arch=(64, 64), learning_rate: float = 3e-4, seed: int = 0,
                 choices: int = 0):
    """A new SB3 ``MultiInputActorCriticPolicy`` on :func:`decision_space`
    with :class:`agents.extractors.CostmapCombined` (torch seeded by
    ``seed``); its action is the decision: w (``points`` numbers, a ``Box``)
    or a stage choice (``Discrete(9)``); with ``choices`` > 0, a choice of
    that many (``Discrete(choices)``, as :mod:`agents.route_offsets`
    decides)."""
    import gymnasium as gym
    import torch
    from stable_baselines3.common.policies import MultiInputActorCriticPolicy

    from .extractors import CostmapCombined

    torch.manual_seed(int(seed))
    action = gym.spaces.Discrete(int(choices)) if choices else \
        gym.spaces.Discrete(len(STAGE_CHOICES)) if form == "stages" else \
        gym.spaces.Box(-1.0, 1.0, (int(points),), np.float32)
    return MultiInputActorCriticPolicy(
        decision_space(env), action,
        lambda _: learning_rate, net_arch=dict(pi=list(net_arch), vf=list(net_arch)),
        features_extractor_class=CostmapCombined,
        features_extractor_kwargs=dict(cnn_dim=int(cnn_dim)), log_std_init=-2.3)


def mirrored(seen: dict, labels: np.ndarray, form: str = "waypoints",
             out: dict | None = None) -> tuple[dict, np.ndarray]:
    """Decisions seen in the mirror of the channel about the ship's track:
    the costmap's columns reversed (it is centred on the ship across), the
    pose's lateral offset, heading and yaw rate negated, and the labels'
    lateral shifts negated (a stage choice c becomes 8 − c, its turns
    negated). The task is symmetric so (the floes, the
    channel and the goal line mirror into another field of the same law),
    and the lattice's route in the mirrored field is the mirror of its
    route, up to ties between routes of equal cost.

    ``out``: arrays (by key, of ``seen``'s shapes) the images are written
    into instead of new ones."""
    if out is None:
        out = {k: np.empty_like(seen[k]) for k in ("costmap", "vector")}
    np.copyto(out["costmap"], seen["costmap"][..., ::-1])
    np.negative(seen["vector"], out=out["vector"])
    return out, len(STAGE_CHOICES) - 1 - labels if form == "stages" else -labels


def with_mirror(seen: dict, labels: np.ndarray, form: str = "waypoints") -> tuple[dict, np.ndarray]:
    """``seen`` and ``labels`` followed by their :func:`mirrored` images, in
    one new array per key: the decisions and their images are held twice
    over in all, not four times as stacking them apart and concatenating
    would (a 500 m costmap is 50 kB a decision)."""
    n = len(labels)
    both = {k: np.empty((2 * n, *v.shape[1:]), dtype=v.dtype) for k, v in seen.items()}
    for k, v in seen.items():
        both[k][:n] = v
    _, flipped = mirrored(seen, labels, form, out={k: both[k][n:] for k in both})
    return both, np.concatenate([labels, flipped])


class _Dagger(LatticeWaypoints):
    """The lattice labels every decision; its waypoint is played with
    probability ``beta``, the student's (``policy``; None: never) otherwise."""

    def __init__(self, env, seed: int, policy, beta: float, coin, form: str, points: int,
                 teacher: str = "lattice", route: dict | None = None):
        super().__init__(env, seed, form=form, points=points, teacher=teacher, **(route or {}))
        self.policy, self.beta, self.coin = policy, float(beta), coin
        self.seen: list[dict] = []
        self.labels: list = []
        self.students: list = []
        self.fields: list[int] = []
        self._field = -1

    def reset(self, seed: int | None = None) -> None:
        super().reset(seed)
        self._field = -1 if seed is None else int(seed)

    def decide(self, obs):
        seen = decision_observation(self.env)
        wanted = self.label()
        self.seen.append(seen)
        self.labels.append(wanted)
        self.fields.append(self._field)
        student = student_decision(self.policy, seen) if self.policy is not None \
            else (-1 if self.form == "stages" else np.full(self.points, np.nan))
        self.students.append(student)
        return wanted if self.coin.random() < self.beta else student


def sail(env_id: str, env_kwargs: dict, policy, beta: float, episodes: int, seed: int,
         label: str, progress: bool, form: str = "waypoints", points: int = 2,
         teacher: str = "lattice", route: dict | None = None):
    """Sail ``episodes`` episodes (seeded ``seed`` + k) under :class:`_Dagger`
    (``route``: the teacher's route settings, :func:`teacher_route`);
    returns (observations, labels, student decisions, returns, the seed of
    each decision's field)."""
    import gymnasium as gym
    env = gym.make(env_id, **env_kwargs)
    driver = _Dagger(env, seed, policy, beta, np.random.default_rng(seed), form, points,
                     teacher, route)
    try:
        returns = sail_fields(env, driver, seed, episodes, label, progress)
    finally:
        env.close()
    return (driver.seen, np.asarray(driver.labels), np.asarray(driver.students), returns,
            np.asarray(driver.fields, dtype=np.int64))


#: the settings of :func:`train_student`
#: (the environment is the leaderboard's, on whose fields a student is judged)
TRAIN_DEFAULTS = dict(env_id=DEFAULT_ENV, env_kwargs={}, form="waypoints", teacher="lattice",
                      teacher_policy=None, points=2, episodes=60,
                      rounds=4, beta=0.5, epochs=20, refit="warm", mirror=True, batch_size=256,
                      learning_rate=3e-4, cnn_dim=128, field_seed=30000, held_out_episodes=8,
                      held_out_seed=50000, keep_labels=False)


def train_student(out: Path, seed: int, progress: bool = True, command: str | None = None,
                  quiet: bool = False, **settings) -> dict:
    """Train a :class:`WaypointStudent` into ``out`` by DAgger from
    :class:`LatticeWaypoints` (see the module's text); returns the record
    written to ``out/waypoints.json``.

    Round r sails ``episodes`` fields seeded ``field_seed`` + r ×
    ``episodes`` + k (round 0: the teacher alone); the student is fitted
    (``epochs`` passes of Adam) after each round on every label so far,
    from its weights before (``refit="warm"``) or from a new network
    seeded alike (``"fresh"``), so that the first rounds' labels are not
    passed over again in every round. ``seed`` seeds the network and the
    fits. The imitation error is then measured on ``held_out_episodes`` fields seeded
    ``held_out_seed`` + k, which the teacher sails. With ``keep_labels``
    every labelled decision is kept in ``out/labels.npz`` (:data:`LABELS`);
    the training is the same with or without it. ``command``: the
    command line the record names (None: none). Each round prints a line
    unless ``quiet``.
    """
    import gymnasium as gym

    import iceenvs  # noqa: F401  (registers the ids)

    from . import observations as obs_rows
    from .pretrain import fit_policy

    unknown = sorted(set(settings) - set(TRAIN_DEFAULTS))
    if unknown:
        raise ValueError(f"unknown settings {unknown}; valid: {', '.join(TRAIN_DEFAULTS)}")
    s = {**TRAIN_DEFAULTS, **settings}
    for name in ("points", "episodes", "epochs", "batch_size", "cnn_dim", "held_out_episodes"):
        if isinstance(s[name], bool) or int(s[name]) != s[name] or s[name] < 1:
            raise ValueError(f"{name} must be an integer >= 1, got {s[name]!r}")
    if isinstance(s["rounds"], bool) or int(s["rounds"]) != s["rounds"] or s["rounds"] < 0:
        raise ValueError(f"rounds must be an integer >= 0, got {s['rounds']!r}")
    if not 0.0 <= s["beta"] <= 1.0:
        raise ValueError(f"beta must lie in [0, 1], got {s['beta']!r}")
    if s["form"] not in FORMS:
        raise ValueError(f"form must be one of {FORMS}, got {s['form']!r}")
    if s["refit"] not in REFITS:
        raise ValueError(f"refit must be one of {REFITS}, got {s['refit']!r}")
    if s["teacher"] not in TEACHERS:
        raise ValueError(f"teacher must be one of {TEACHERS}, got {s['teacher']!r}")
    route = None
    if s["teacher_policy"] is not None:
        kind, route = teacher_route(s["teacher_policy"])
        if kind != s["teacher"]:
            raise ValueError(f"the teacher's policy plans as the {kind}: give teacher {kind!r}, "
                             f"got {s['teacher']!r}")
    if s["form"] == "stages" and s["points"] != 2:
        raise ValueError(f"form 'stages' decides two waypoints, got points {s['points']!r}")
    choices = s["form"] == "stages"
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    probe = gym.make(s["env_id"], **s["env_kwargs"])

    def new_student():
        return make_student(probe, form=s["form"], points=s["points"], cnn_dim=s["cnn_dim"],
                            learning_rate=s["learning_rate"], seed=seed)

    policy = new_student()
    seen: dict | None = None  # every decision so far, one float32 array per key
    labels = np.empty(0, dtype=np.int64) if choices else np.empty((0, s["points"]))
    round_of, field_of = np.empty(0, dtype=np.int64), np.empty(0, dtype=np.int64)
    rounds = []
    began = time.perf_counter()
    for r in range(s["rounds"] + 1):
        start = time.perf_counter()
        beta = 1.0 if r == 0 else float(s["beta"]) ** r
        new, wanted, _, returns, fields = sail(
            s["env_id"], s["env_kwargs"], policy if r else None, beta, s["episodes"],
            s["field_seed"] + r * s["episodes"], f"round {r} (beta {beta:.3g})", progress,
            s["form"], s["points"], s["teacher"], route)
        new = obs_rows.stack(new)
        seen = new if seen is None else {k: np.concatenate([seen[k], new[k]]) for k in seen}
        del new
        labels = np.concatenate([labels, wanted])
        round_of = np.concatenate([round_of, np.full(len(wanted), r)])
        field_of = np.concatenate([field_of, fields])
        if r and s["refit"] == "fresh":
            policy = new_student()
        data, targets = seen, labels if choices else np.clip(labels, -1.0, 1.0)
        if s["mirror"]:
            data, targets = with_mirror(data, targets, s["form"])
        fit = fit_policy(policy, data, targets, None,
                         epochs=s["epochs"], batch_size=s["batch_size"],
                         learning_rate=s["learning_rate"], seed=seed * 1000 + r)
        del data  # the mirrored copy, until the next round's fit
        rounds.append({"round": r, "beta": beta, "decisions": len(wanted),
                       "mean_return": float(np.mean(returns)),
                       **{k: v for k, v in fit.items() if k.startswith("action_")},
                       "seconds": round(time.perf_counter() - start, 1)})
        if not quiet:
            print(f"round {r} (beta {beta:.3g}): {len(wanted)} decisions, mean return "
                  f"{np.mean(returns):.1f}, {fit_text(rounds[-1])}, "
                  f"{rounds[-1]['seconds']:.0f} s", flush=True)
    probe.close()
    held_seen, wanted, students, _, held_fields = sail(
        s["env_id"], s["env_kwargs"], policy, 1.0, s["held_out_episodes"], s["held_out_seed"],
        "held out", progress, s["form"], s["points"], s["teacher"], route)
    if s["keep_labels"]:
        held_seen = obs_rows.stack(held_seen)
        np.savez_compressed(out / LABELS, labels=labels, round=round_of, field=field_of, **seen,
                            held_labels=wanted, held_field=held_fields,
                            **{"held_" + k: v for k, v in held_seen.items()})
    del held_seen
    if choices:
        held = {"action_accuracy": float(np.mean(students == wanted))}
    else:
        wanted = np.clip(wanted, -1.0, 1.0)
        held = {"action_mse": float(np.mean((students - wanted) ** 2)),
                "action_variance": float(np.var(wanted))}
    record = {"settings": {**s, "seed": seed}, "rounds": rounds,
              "held_out": {"decisions": len(wanted), **held},
              "seconds": round(time.perf_counter() - began, 1),
              "command": command}
    policy.save(str(out / STUDENT))
    (out / RECORD).write_text(json.dumps(record, indent=2) + "\n")
    return record


def fit_text(fit: dict) -> str:
    """A fit's error in words: the share of the teacher's choices that are
    the student's, or the squared error as a share of the labels' variance."""
    if "action_accuracy" in fit:
        return f"agrees on {fit['action_accuracy']:.3f} of the choices"
    return f"error {fit['action_mse'] / max(fit['action_variance'], 1e-12):.3f} of the variance"


def report(runs, out: Path) -> dict:
    """Gather the records of the training runs ``runs`` (directories of
    :func:`train_student`) into ``out``: ``waypoints.json`` (each run's
    record, by its directory as given) and ``waypoints.md`` (a table of each
    seed's rounds: the decisions added, the mean return of the round's
    episodes and the fit (:func:`fit_text`); then the same on the held-out
    fields)."""
    records = gather_records(runs, RECORD, "agents.waypoints train")
    lines = ["| run | round | β | decisions | mean return of the round's episodes "
             "| fit on all labels so far |", "|---|---|---|---|---|---|"]
    for name, record in records.items():
        for r in record["rounds"]:
            lines.append(f"| {name} | {r['round']} | {r['beta']:.3g} | {r['decisions']} "
                         f"| {r['mean_return']:.1f} "
                         f"| {fit_text(r)} |")
    lines += ["", "| run | seed | form | teacher | fits | held-out decisions "
              "| the student on them | fitted on (with mirror images) | training [min] |",
              "|---|---|---|---|---|---|---|---|---|"]
    for name, record in records.items():
        held, s = record["held_out"], record["settings"]
        fitted = sum(r["decisions"] for r in record["rounds"]) * (2 if s.get("mirror") else 1)
        lines.append(f"| {name} | {s['seed']} | {s.get('form', 'waypoints')} "
                     f"| {s.get('teacher', 'lattice')}"
                     f"{' (its own settings)' if s.get('teacher_policy') else ''} "
                     f"| {s.get('refit', 'warm')}, {s['epochs']} epochs | {held['decisions']} "
                     f"| {fit_text(held)} | {fitted} | {record['seconds'] / 60:.1f} |")
    first = next(iter(records.values()))["settings"]
    lines += ["", f"Fields: {first['episodes']} a round seeded {first['field_seed']} + k "
              f"(round r from {first['field_seed']} + r × {first['episodes']}); held out: "
              f"{first['held_out_episodes']} seeded {first['held_out_seed']} + k, sailed by "
              f"the teacher. Errors of waypoints are of the decisions clipped to [−1, 1].",
              ""]
    write_gathered(out, RECORD, records, "waypoints.md", lines)
    return records


def main(argv=None) -> int:
    p = argparse.ArgumentParser(prog="python -m agents.waypoints", description=__doc__.split(
        "\n\n")[0], formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = p.add_subparsers(dest="command", required=True)
    t = sub.add_parser("train", help="train a student by DAgger from the lattice's waypoints")
    t.add_argument("--seed", type=int, default=1)
    t.add_argument("--out", type=Path, required=True)
    for name in ("points", "episodes", "rounds", "epochs", "field_seed", "held_out_episodes",
                 "held_out_seed"):
        t.add_argument("--" + name.replace("_", "-"), type=int, default=TRAIN_DEFAULTS[name])
    t.add_argument("--form", choices=FORMS, default=TRAIN_DEFAULTS["form"],
                   help="a decision: two lateral shifts (waypoints, default) or one of "
                        "the lattice's nine two-stage choices (stages)")
    t.add_argument("--teacher", choices=TEACHERS, default=TRAIN_DEFAULTS["teacher"],
                   help="the lattice on the floes (lattice, default; privileged) or on the "
                        "environment's costmap (costmap-lattice; what the student sees)")
    t.add_argument("--teacher-policy", default=None, metavar="POLICY",
                   help="plan the teacher's routes with a planner's own settings: a lattice "
                        "planner's policy string, or agents.tuned_lattice:ByConcentration's "
                        "(python -m agents.tuned_lattice best or combine prints one); the "
                        "follower's pace and pursuit stay its own")
    t.add_argument("--refit", choices=REFITS, default=TRAIN_DEFAULTS["refit"],
                   help="fit each round's student from the last round's weights (warm, "
                        "default) or from a new network (fresh)")
    t.add_argument("--beta", type=float, default=TRAIN_DEFAULTS["beta"])
    t.add_argument("--no-mirror", dest="mirror", action="store_false",
                   help="fit on the decisions seen only, not also on their mirror images")
    t.add_argument("--env-kwargs", nargs="*", default=[], metavar="KEY=VALUE",
                   help="gymnasium.make keywords of the fields sailed (YAML values)")
    t.add_argument("--keep-labels", action="store_true",
                   help=f"keep every labelled decision in OUT/{LABELS}, of the rounds and of "
                        "the held-out fields (about 0.2 GB a run on a 500 m costmap)")
    t.add_argument("--no-progress", action="store_true")
    from .waypoint_rl import FINETUNE_DEFAULTS

    f = sub.add_parser("finetune", help="train a student further by PPO on the reward, one "
                                         "action a decision (agents.waypoint_rl)")
    f.add_argument("--run", type=Path, required=True, help="the student's run directory")
    f.add_argument("--seed", type=int, default=1)
    f.add_argument("--out", type=Path, required=True)
    helps = {"paired_horizon": "0: the environment's reward (default); H: each decision's "
                               "advantage over the costmap lattice in H steps, paired on the "
                               "same episode from a snapshot (privileged; with --gamma 0)"}
    helps["residual"] = ("the action corrects the costmap lattice's decision, starting at "
                         "zero; play the run with agents.waypoints:WaypointResidual")
    helps["privileged_critic"] = ("the critic also reads the lattice's price of the ice ahead "
                                  "and the field's concentration (privileged; agents.privileged)")
    for name, value in FINETUNE_DEFAULTS.items():
        if isinstance(value, bool):
            f.add_argument("--" + name.replace("_", "-"), action="store_true",
                           help=helps.get(name))
        else:
            f.add_argument("--" + name.replace("_", "-"), type=type(value), default=value,
                           help=helps.get(name))
    f.add_argument("--no-progress", action="store_true")
    r = sub.add_parser("report", help="gather runs' records into one record and a table")
    r.add_argument("runs", nargs="+", type=Path, help="run directories of train or finetune "
                                                       "(gathered apart)")
    r.add_argument("--out", type=Path, required=True)
    argv = sys.argv[1:] if argv is None else list(argv)
    args = p.parse_args(argv)
    if args.command == "report":
        from .waypoint_rl import FINETUNE_RECORD, finetune_report

        tuned = [run for run in args.runs if (run / FINETUNE_RECORD).is_file()]
        trained = [run for run in args.runs if run not in tuned]
        try:
            if trained:
                report(trained, args.out)
                print((args.out / "waypoints.md").read_text())
            if tuned:
                finetune_report(tuned, args.out)
                print((args.out / "finetune.md").read_text())
        except (ValueError, FileNotFoundError) as exc:
            p.error(str(exc))
        return 0
    if args.command == "finetune":
        from .waypoint_rl import finetune

        try:
            record = finetune(args.run, args.out, args.seed, progress=not args.no_progress,
                              command=shlex.join(["python", "-m", "agents.waypoints", *argv]),
                              **{k: getattr(args, k) for k in FINETUNE_DEFAULTS})
        except (ValueError, FileNotFoundError) as exc:
            p.error(str(exc))
        print(f"{args.out}: {record['decisions']} decisions, {record['episodes']} episodes in "
              f"{record['seconds']:.0f} s; mean return by {record['window']} episodes: "
              f"{record['mean_env_return_by_window']}" + (
                  f"; reward {record['reward']}, its sums {record['mean_return_by_window']}"
                  if record["settings"]["paired_horizon"] else ""))
        return 0
    settings = {k: getattr(args, k) for k in ("form", "teacher", "teacher_policy", "refit",
                                              "points", "episodes",
                                              "rounds", "epochs",
                                              "field_seed",
                                              "held_out_episodes", "held_out_seed", "beta",
                                              "mirror", "keep_labels")}
    from .envs import parse_key_values

    try:
        settings["env_kwargs"] = parse_key_values(args.env_kwargs)
        record = train_student(args.out, args.seed, progress=not args.no_progress,
                               command=shlex.join(["python", "-m", "agents.waypoints", *argv]),
                               **settings)
    except (ValueError, FileNotFoundError) as exc:
        p.error(str(exc))
    print(f"{args.out}: {sum(r['decisions'] for r in record['rounds'])} decisions in "
          f"{record['seconds']:.0f} s; on the held-out fields the student "
          f"{fit_text(record['held_out'])}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
