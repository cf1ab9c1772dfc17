"""The costmap lattice with its parameters learned from the reward:
``python -m agents.tuned_lattice``.

The costmap lattice (:class:`agents.planners.CostmapLatticePlanner`) plans
on exactly what a costmap learner sees, and its settings (the price of a
metre of detour, how steep a route may turn, how far ahead the pure
pursuit aims, how often it replans, how far from the edges it keeps) were
chosen for the lattice that sees every floe, by hand. Here they are the
parameters of a sensor-only policy, searched by Optuna's TPE sampler for
the highest mean return on fields of the search's own: a policy search of
a few parameters, with the lattice's dynamic programming inside the
policy. It is a learner that searches, and a planner all the same: what
it learns are seven numbers, not a network.

* **The parameters** (:data:`SPACE`): ``metre_cost`` (as a factor on the
  reward's own trade-off), ``blur`` and ``fade`` (the ice's price smoothed
  across the channel, and weighed down with the distance ahead:
  :class:`agents.planners.LatticePlanner`), ``max_slope``,
  ``lookahead``, ``replan_steps`` and ``edge_margin``. The first trial of
  every search is the planner as it is (:data:`DEFAULTS`), so each search
  shows what the tuning added on its own fields.
* **The fields**: search s sails ``episodes`` fields at each
  concentration, seeded :data:`SEARCH_SEED` + 1000 s + k, the same fields
  for each of its trials (so that trials are compared paired), and never
  the leaderboard's (10000 + k) nor the held-out fields (50000 + k).
* **The record** (``--out``, written after every trial, so that an
  interrupted search loses nothing and ``--resume`` goes on from it):
  ``search.json`` (each trial's parameters, its mean return at each
  concentration and over all, and its wall time; the best trial and its
  policy, to play with ``python -m agents.leaderboard --policies``).

Search, then play the best on the board's fields::

    python -m agents.tuned_lattice search --seed 1 --trials 24 --out runs/tuned/seed_1
    python -m agents.tuned_lattice report runs/tuned/seed_* --out runs/tuned
    python -m agents.leaderboard --env-kwargs costmap_ahead=500 \\
        --policies "swath,tuned-s1=$(python -m agents.tuned_lattice best runs/tuned/seed_1)"
"""
from __future__ import annotations

import argparse
import json
import math
import shlex
import sys
import time
from pathlib import Path

import numpy as np

from iceenvs.ship_controllers import StraightLineController

from .leaderboard import DEFAULT_ENV
from .planners import (CostmapLatticePlanner, check_settings, concentration_bounds,
                       planner_for)

__all__ = ["SPACE", "DEFAULTS", "SEARCH_SEED", "SEARCH", "policy_of", "search", "read_search",
           "best_policy", "ByConcentration", "by_concentration_policy", "report", "main"]

#: each parameter's range: (low, high, log scale, integer); ``metre_cost`` is
#: a factor on the environment's own trade-off, ``fade_rate`` [1/m] is
#: 1 / ``fade`` (0: no fade)
SPACE = {
    "metre_cost": (0.25, 4.0, True, False),
    "blur": (0.0, 4.0, False, False),
    "fade_rate": (0.0, 0.01, False, False),
    "max_slope": (0.25, 0.8, False, False),
    "lookahead": (15.0, 60.0, False, False),
    "replan_steps": (2, 10, False, True),
    "edge_margin": (4.0, 20.0, False, False),
}
#: the costmap lattice as it is (:class:`agents.planners.LatticePlanner`'s own settings)
DEFAULTS = {"metre_cost": 1.0, "blur": 0.0, "fade_rate": 0.0, "max_slope": 0.5,
            "lookahead": 30.0, "replan_steps": 5, "edge_margin": 10.0}
#: search s sails the fields seeded SEARCH_SEED + 1000 s + k
SEARCH_SEED = 110_000
#: the search record, in ``--out``
SEARCH = "search.json"
PLANNER = "agents.planners:CostmapLatticePlanner"


def _text(value: float) -> str:
    """A value as a decimal that YAML reads as a number (no exponent)."""
    return f"{value:.6f}".rstrip("0").rstrip(".") if not float(value).is_integer() \
        else str(int(value))


def policy_of(params: dict, metre_cost: float) -> str:
    """The policy (``module:Class?key=value&...``) of a trial's parameters,
    the factor on ``metre_cost`` [N s/m] (the environment's own) made
    absolute."""
    unknown = set(params) - set(SPACE)
    if unknown:
        raise ValueError(f"unknown parameters {sorted(unknown)}; the search has {list(SPACE)}")
    kwargs = {}
    for name, value in params.items():
        if name == "metre_cost":
            kwargs[name] = round(float(value) * metre_cost)
        elif name == "fade_rate":
            if value > 0:
                kwargs["fade"] = round(1.0 / float(value), 1)
        elif name == "replan_steps":
            kwargs[name] = int(value)
        else:
            kwargs[name] = round(float(value), 3)
    return PLANNER + "?" + "&".join(f"{k}={_text(v)}" for k, v in kwargs.items())


def _env_metre_cost(env_id: str, env_kwargs: dict) -> float:
    import gymnasium as gym

    import iceenvs  # noqa: F401

    from .planners import DEFAULT_METRE_COST

    env = gym.make(env_id, **env_kwargs)
    try:
        return float(getattr(env.unwrapped, "metre_cost", None) or DEFAULT_METRE_COST)
    finally:
        env.close()


def _check(trials: int, episodes: int, concentrations, processes: int, seed: int) -> None:
    for name, value, low in (("trials", trials, 1), ("episodes", episodes, 2),
                             ("processes", processes, 1), ("seed", seed, 0)):
        if isinstance(value, bool) or int(value) != value or value < low:
            raise ValueError(f"{name} must be an integer >= {low}, got {value!r}")
    if not concentrations or any(not (0.0 < float(a) < 1.0) for a in concentrations):
        raise ValueError(f"concentrations must lie in (0, 1), got {concentrations!r}")


def search(out, *, seed: int = 1, trials: int = 24, episodes: int = 8,
           concentrations=(0.2, 0.3, 0.4, 0.5), env_id: str = DEFAULT_ENV,
           env_kwargs: dict | None = None, processes: int = 2, resume: bool = False,
           progress: bool = True, command: str = "") -> dict:
    """Search the costmap lattice's parameters (:data:`SPACE`) for the
    highest mean return on ``episodes`` fields at each concentration
    (seeded :data:`SEARCH_SEED` + 1000 ``seed`` + k), ``trials`` trials of
    Optuna's TPE sampler (seeded ``seed``), the first the planner as it is.
    Writes ``out``/``search.json`` after every trial and returns its
    record. ``resume`` goes on from a search already in ``out`` (with the
    same settings); without it, a search there is refused."""
    import optuna
    from tqdm.auto import tqdm

    from physics.provenance import source_commit

    from .leaderboard import host_signature, run_leaderboard
    from .rollouts import policy_recipe, process_pool

    _check(trials, episodes, concentrations, processes, seed)
    env_kwargs = {"costmap_ahead": 500.0, **(env_kwargs or {})}
    out = Path(out)
    fields = SEARCH_SEED + 1000 * int(seed)
    settings = dict(env_id=env_id, env_kwargs=env_kwargs, seed=int(seed), fields_seed=fields,
                    episodes=int(episodes), concentrations=[float(a) for a in concentrations],
                    space={k: list(v) for k, v in SPACE.items()})
    done = []
    if (out / SEARCH).exists():
        if not resume:
            raise FileExistsError(f"{out / SEARCH} holds a search: pass resume=True "
                                  f"(--resume) to go on with it, or choose another out")
        old = read_search(out)
        if old["settings"] != json.loads(json.dumps(settings)):
            raise ValueError(f"{out / SEARCH} was searched with other settings: "
                             f"{old['settings']}")
        done = old["trials"]
    metre_cost = _env_metre_cost(env_id, env_kwargs)
    optuna.logging.set_verbosity(optuna.logging.WARNING)
    study = optuna.create_study(direction="maximize",
                                sampler=optuna.samplers.TPESampler(seed=int(seed)))
    distributions = {
        name: (optuna.distributions.IntDistribution(int(low), int(high)) if integer else
               optuna.distributions.FloatDistribution(low, high, log=log))
        for name, (low, high, log, integer) in SPACE.items()}
    for trial in done:
        study.add_trial(optuna.trial.create_trial(params=trial["params"],
                                                  distributions=distributions,
                                                  value=trial["value"]))
    if not done:
        study.enqueue_trial(DEFAULTS)
    out.mkdir(parents=True, exist_ok=True)
    record = dict(settings=settings, metre_cost=metre_cost, trials=list(done),
                  command=command, commit=source_commit(), host=host_signature())
    with process_pool(processes) as pool:
        for n in tqdm(range(len(done), trials), desc="trials", unit="trial",
                      disable=not progress, initial=len(done), total=trials):
            trial = study.ask(distributions)
            policy = policy_of(trial.params, metre_cost)
            t0 = time.perf_counter()
            # each trial's planner under a name of its own: the pool's workers keep policies by name
            name = f"trial-{n}"
            board = run_leaderboard(env_id, concentrations, {name: policy_recipe(policy)},
                                    episodes=episodes, seed=fields, processes=processes,
                                    env_kwargs=env_kwargs, progress=False, pool=pool)
            record["trials"].append(_trial_record(
                n, trial.params, policy, {a: played[name] for a, played in board.items()},
                time.perf_counter() - t0))
            study.tell(trial, record["trials"][-1]["value"])
            _write(out, record)
    return _write(out, record)


def _trial_record(n: int, params: dict, policy: str, board: dict, wall: float) -> dict:
    returns = {a: [e["ret"] for e in episodes] for a, episodes in board.items()}
    every = [r for rs in returns.values() for r in rs]
    return dict(number=n, params=params, policy=policy, value=float(np.mean(every)),
                by_concentration={a: float(np.mean(rs)) for a, rs in returns.items()},
                standard_error=float(np.std(every, ddof=1) / math.sqrt(len(every))),
                outside_steps=int(sum(e.get("outside_steps", 0) for episodes in board.values()
                                      for e in episodes)),
                wall_s=round(wall, 1))


def _best_trial(record: dict) -> dict:
    """The trial of the highest mean return of a search's ``record``."""
    return max(record["trials"], key=lambda t: t["value"])


def _write(out: Path, record: dict) -> dict:
    best = _best_trial(record)
    record["best"] = dict(number=best["number"], value=best["value"], policy=best["policy"],
                          gain_over_first=best["value"] - record["trials"][0]["value"])
    (out / SEARCH).write_text(json.dumps(record, indent=1) + "\n")
    return record


def read_search(directory) -> dict:
    """The record of the search in ``directory``."""
    path = Path(directory) / SEARCH
    if not path.exists():
        raise FileNotFoundError(f"no search in {directory}: {path} is missing "
                                f"(python -m agents.tuned_lattice search --out {directory})")
    return json.loads(path.read_text())


def best_policy(directory) -> str:
    """The best trial's policy of the search in ``directory``."""
    return read_search(directory)["best"]["policy"]


class ByConcentration(StraightLineController):
    """The costmap lattice with settings of its own for each range of the
    episode's ice concentration (not privileged): the planner of
    ``settings[i]`` (keyword arguments of
    :class:`agents.planners.CostmapLatticePlanner`) sails an episode whose
    concentration lies below ``bounds[i]`` (and at or above ``bounds[i - 1]``);
    the last sails those at or above the last bound. The concentration is
    the observation's ``concentration`` entry at the episode's first step,
    an entry every learner of the environment sees too.

    It joins searches made at different concentrations, as
    :func:`by_concentration_policy` writes it from their directories."""

    reads_environment = "its costmap"

    def __init__(self, env, seed: int = 0, *, bounds, settings):
        edges = concentration_bounds(bounds)
        check_settings(edges, settings)
        super().__init__(env, seed)
        if "concentration" not in self._index:
            raise ValueError(f"ByConcentration reads the observation's concentration entry, "
                             f"which {type(self.unwrapped).__name__} has not")
        self.bounds = edges
        self.planners = [CostmapLatticePlanner(env, seed, **s) for s in settings]
        self.chosen = None

    @property
    def decision_times(self) -> list[float]:
        """The episode's plan times: the chosen planner's."""
        return [] if self.chosen is None else self.chosen.decision_times

    def reset(self, seed: int | None = None) -> None:
        super().reset(seed)
        for planner in self.planners:
            planner.reset(seed)
        self.chosen = None

    def act(self, obs):
        if self.chosen is None:
            self.chosen = planner_for(self.bounds, self.planners, self._reader(obs))
        return self.chosen.act(obs)


def by_concentration_policy(bounds, directories) -> str:
    """The :class:`ByConcentration` policy of the best trials of the
    searches in ``directories``, one more than ``bounds``: the first
    search's settings below the first bound, and so on."""
    from .policy import parse_reference

    bounds = concentration_bounds(bounds)
    if len(directories) != len(bounds) + 1:
        raise ValueError(f"{len(bounds)} bounds take {len(bounds) + 1} searches, "
                         f"got {len(directories)}")
    settings = [parse_reference(best_policy(d))[2] for d in directories]
    text = ", ".join("{" + ", ".join(f"{k}: {_text(v)}" for k, v in s.items()) + "}"
                     for s in settings)
    return (f"agents.tuned_lattice:ByConcentration?bounds=[{','.join(f'{b:g}' for b in bounds)}]"
            f"&settings=[{text}]")


def report(directories, out) -> dict:
    """``out``/``search.md`` and ``search.png``: each search's first trial
    (the planner as it is), its best, and the best's parameters; the mean
    return of every trial, and the best so far, against the trial's
    number. ``out``/``search.json`` keeps every search's trials."""
    records = {Path(d).name: read_search(d) for d in directories}
    if not records:
        raise ValueError("report needs at least one search directory")
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    concentrations = next(iter(records.values()))["settings"]["concentrations"]
    keys = [f"{a:g}" for a in concentrations]
    lines = ["| search | fields | trials | wall [min] | as it is | best (trial) | "
             + " | ".join(f"gain at A = {k}" for k in keys) + " | gain over all |",
             "|---" * (7 + len(keys)) + "|"]
    for name, r in records.items():
        first, best = r["trials"][0], _best_trial(r)
        fields = r["settings"]["episodes"] * len(r["settings"]["concentrations"])
        gains = " | ".join(f"{best['by_concentration'][k] - first['by_concentration'][k]:+.1f}"
                           for k in keys)
        lines.append(f"| {name} | {fields} | {len(r['trials'])} | "
                     f"{sum(t['wall_s'] for t in r['trials']) / 60:.0f} | "
                     f"{first['value']:.1f} | {best['value']:.1f} ({best['number']}) | "
                     f"{gains} | {best['value'] - first['value']:+.1f} |")
    lines += ["", "The best trials' settings, beside the planner's own:", "",
              "| search | " + " | ".join(_SHOWN) + " |", "|---" * (1 + len(_SHOWN)) + "|",
              "| as it is | " + " | ".join(_setting(k, DEFAULTS) for k in _SHOWN) + " |"]
    for name, r in records.items():
        best = _best_trial(r)
        lines.append(f"| {name} | " + " | ".join(_setting(k, best["params"]) for k in _SHOWN)
                     + " |")
    lines += ["", "Mean returns over the search's own fields (its trials are paired on "
              "them); metre_cost as a factor on the reward's own trade-off."]
    (out / "search.md").write_text("\n".join(lines) + "\n")
    summary = {name: dict(trials=[_brief(t) for t in r["trials"]], best=r["best"],
                          settings=r["settings"], command=r.get("command", ""),
                          commit=r.get("commit"))
               for name, r in records.items()}
    (out / SEARCH).write_text(json.dumps(summary, indent=1) + "\n")
    _plot(records, out / "search.png")
    return summary


def _brief(trial: dict) -> dict:
    """A trial as the report keeps it: its parameters and mean returns to
    four significant figures (the search's own record keeps them whole)."""
    def g(v):
        return float(f"{v:.4g}")
    return dict(number=trial["number"], value=g(trial["value"]),
                by_concentration={a: g(v) for a, v in trial["by_concentration"].items()},
                params={k: (v if isinstance(v, int) else g(v)) for k, v in trial["params"].items()},
                wall_s=trial["wall_s"])


#: the settings as the report shows them (fade [m] = 1 / fade_rate)
_SHOWN = ("metre_cost", "blur [m]", "fade [m]", "max_slope", "lookahead [m]", "replan_steps",
          "edge_margin [m]")


def _setting(shown: str, params: dict) -> str:
    name = shown.split(" ")[0]
    if name == "fade":
        return "none" if params["fade_rate"] <= 0 else f"{1.0 / params['fade_rate']:.0f}"
    if SPACE[name][3]:
        return str(int(params[name]))
    return f"{float(params[name]):.2g}" if name in ("metre_cost", "max_slope") \
        else f"{float(params[name]):.1f}"


def _plot(records: dict, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6.4, 3.6))
    for i, (name, r) in enumerate(records.items()):
        values = [t["value"] for t in r["trials"]]
        colour = f"C{i}"
        ax.plot(range(len(values)), values, "o", ms=3, color=colour, alpha=0.6)
        ax.plot(range(len(values)), np.maximum.accumulate(values), "-", color=colour,
                label=f"{name} (best so far)")
        ax.axhline(values[0], color=colour, lw=0.8, ls=":")
    ax.set_xlabel("trial (0: the costmap lattice as it is, dotted)")
    ax.set_ylabel("mean return on the search's fields")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="python -m agents.tuned_lattice",
                                     description=__doc__.split("\n\n")[0])
    sub = parser.add_subparsers(dest="command", required=True)
    s = sub.add_parser("search", help="search the costmap lattice's parameters")
    s.add_argument("--seed", type=int, default=1)
    s.add_argument("--trials", type=int, default=24)
    s.add_argument("--episodes", type=int, default=8, help="fields at each concentration")
    s.add_argument("--concentrations", default="0.2,0.3,0.4,0.5")
    s.add_argument("--env", default=DEFAULT_ENV)
    s.add_argument("--env-kwargs", nargs="*", default=[], metavar="KEY=VALUE")
    s.add_argument("--processes", type=int, default=2)
    s.add_argument("--resume", action="store_true")
    s.add_argument("--no-progress", action="store_true")
    s.add_argument("--out", required=True)
    r = sub.add_parser("report", help="tables and a figure of searches")
    r.add_argument("directories", nargs="+")
    r.add_argument("--out", required=True)
    b = sub.add_parser("best", help="print a search's best policy")
    b.add_argument("directory")
    c = sub.add_parser("combine", help="print the policy that sails each range of concentration "
                                       "with the best settings of a search of its own")
    c.add_argument("--bounds", required=True,
                   help="comma-separated concentrations between the searches' ranges")
    c.add_argument("directories", nargs="+", help="the searches, one more than the bounds")
    return parser


def main(argv: list[str] | None = None) -> int:
    from .envs import parse_key_values

    args = build_parser().parse_args(argv)
    if args.command == "search":
        try:
            kwargs = parse_key_values(args.env_kwargs)
        except ValueError as err:
            raise SystemExit(str(err)) from None
        command = "python -m agents.tuned_lattice " + shlex.join(
            sys.argv[1:] if argv is None else argv)
        try:
            record = search(args.out, seed=args.seed, trials=args.trials,
                            episodes=args.episodes,
                            concentrations=[float(a) for a in args.concentrations.split(",")],
                            env_id=args.env, env_kwargs=kwargs, processes=args.processes,
                            resume=args.resume, progress=not args.no_progress, command=command)
        except (ValueError, FileExistsError) as err:
            raise SystemExit(str(err)) from None
        print(f"best: trial {record['best']['number']}, mean return "
              f"{record['best']['value']:.2f} ({record['best']['gain_over_first']:+.2f} over "
              f"the planner as it is): {record['best']['policy']}")
    elif args.command == "report":
        report(args.directories, args.out)
        print(Path(args.out, "search.md").read_text())
    elif args.command == "combine":
        try:
            bounds = [float(b) for b in args.bounds.split(",")]
            print(by_concentration_policy(bounds, args.directories))
        except (ValueError, FileNotFoundError) as err:
            raise SystemExit(str(err)) from None
    else:
        print(best_policy(args.directory))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
