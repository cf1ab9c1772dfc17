"""The ship-navigation leaderboard: ``python -m agents.leaderboard``.

Every policy sails the same seeded ice fields at each concentration
(episode k of every policy and every concentration seeded ``--seed`` + k:
the same draws, so paired), and the table gives per policy and
concentration the mean and standard error of the return and of
AUTO-IceNav's metrics, and the metrics normalised by the straight line's
on the same field (the mean over the fields of the per-field ratio). The
return and the impulse per metre are also paired with the straight line's
over the fields of all concentrations together, the task's spread.

Route choice *pays* at a concentration when the best planner meets at
most 0.7 times the straight line's ice impulse per metre (the ratio of
the means over the fields), sailing at most 10 % further.

Output in ``--out`` (default ``runs/leaderboard``; the documented board is
``--out docs/agents/leaderboard``): the record, ``leaderboard.json`` (the
summaries, the paired comparisons, and the recipe of each policy: the
command that played it and the source commit it ran; host and date), with ``leaderboard.md`` (its
tables) and ``leaderboard.png`` (impulse per metre and return against
concentration), and the episodes behind it, ``episodes.json`` (every
episode's final metrics: what ``--merge`` pairs new policies with, and
``--render`` summarises again; large, and not committed with a documented
record). The record keeps its summaries to eight significant figures (its
tables show at most four), and ``--render`` writes it back so::

    python -m agents.leaderboard [--env iceenvs/ShipNavigation-v1]
        [--concentrations 0.2,0.3,0.4,0.5] [--episodes 20] [--seed 10000]
        [--policies NAMES|[NAME=]module:Class] [--trained NAME=RUN_DIR[@STEPS] ...]
        [--merge [--replace NAMES]]
        [--env-kwargs key=value ...] [--processes 2] [--out DIR]
    python -m agents.leaderboard --render [--out DIR]   # the table and plot from the JSON
    python -m agents.leaderboard --render --against swath [--group NAME=P1,P2,P3] [--out DIR]

``--against NAME`` writes ``against-NAME.md``: every policy's return paired
with NAME's field by field, at each concentration and over all, where
``--group`` makes one policy of several (a learner's training seeds: its
return on a field is the mean of theirs).
"""
from __future__ import annotations

import argparse
import datetime
import json
import math
import platform
import shlex
import sys
import time
from pathlib import Path

import numpy as np

from physics.provenance import source_commit

from .metrics import METRIC_UNITS, rounding_noise, significant

__all__ = ["run_leaderboard", "policy_label", "summarise_board", "pooled_comparison",
           "board_markdown", "record_commands", "grouped", "against_markdown",
           "plot_board", "main",
           "NORMALISED", "SHOWN", "ROUTE_CHOICE_RATIO", "DETOUR_LIMIT"]

DEFAULT_ENV = "iceenvs/ShipNavigation-v1"
DEFAULT_OUT = Path("runs/leaderboard")
#: the record and the episodes behind it, in ``--out``
RECORD, EPISODES = "leaderboard.json", "episodes.json"
#: the metrics normalised by the straight line's on the same field
NORMALISED = ("impulse_per_metre", "energy_to_ice", "mean_impulse", "max_impulse", "path_length")
#: the metrics of the main table, shown as :data:`agents.metrics.METRIC_UNITS`
#: says: (logged name, header, scale, unit)
SHOWN = tuple((name, METRIC_UNITS[name].header, METRIC_UNITS[name].scale, METRIC_UNITS[name].unit)
              for name in ("impulse_per_metre", "energy_to_ice", "path_length", "collisions",
                           "collided_floes", "mean_impulse", "max_impulse", "mean_mass_hit"))
#: route choice pays when the best planner's impulse per metre is at most this
#: times the straight line's ...
ROUTE_CHOICE_RATIO = 0.7
#: ... sailing at most this times its path
DETOUR_LIMIT = 1.1


def run_leaderboard(env_id: str, concentrations, recipes: dict, *, episodes: int, seed: int,
                    processes: int, env_kwargs: dict | None = None,
                    progress: bool = True, pool=None) -> dict:
    """``{concentration (str): {policy: [episode dicts]}}`` of
    :func:`agents.rollouts.evaluate_in_processes` at each concentration
    (in ``pool``, a :func:`agents.rollouts.process_pool`, where given)."""
    from .rollouts import evaluate_in_processes

    board = {}
    for a in concentrations:
        kwargs = {**(env_kwargs or {}), "concentration": float(a)}
        board[f"{float(a):g}"] = evaluate_in_processes(
            env_id, kwargs, recipes, episodes=episodes, seed=seed, processes=processes,
            progress=progress, pool=pool)
    return board


def host_signature() -> str:
    """What the trajectories depend on beyond the seed: the library versions
    and the CPU features NumPy and Numba compute with. A DEM trajectory is
    chaotic, so a sum rounded otherwise (another SIMD width, another
    version) sends a ship along another trajectory from the same field."""
    import numba

    try:
        from numpy._core._multiarray_umath import __cpu_dispatch__, __cpu_features__
        simd = " ".join(f for f in __cpu_dispatch__ if __cpu_features__.get(f))
    except ImportError:            # a NumPy without these tables: the version alone
        simd = "?"
    try:
        import llvmlite.binding as llvm
        cpu = numba.config.CPU_NAME or llvm.get_host_cpu_name()
    except (ImportError, AttributeError):
        cpu = "?"
    return (f"{platform.machine()}, numpy {np.__version__} ({simd}), "
            f"numba {numba.__version__} ({cpu})")


#: which of the two impulse ratios a reader should read, and why they can disagree
RATIO_NOTE = (
    "**Which ratio to read.** The *ratio of means* (the policy's mean impulse per metre "
    "over the straight line's on the same fields) ranks the policies: it weighs each "
    "field by the ice there is to meet. The mean of the per-field ratios weighs every "
    "field alike, and a field on which the straight line happened to meet little ice "
    "gives a large ratio whatever the policy did, so one such field can carry the mean; "
    "it shows how the ratio varies between fields. A † marks a policy whose two ratios "
    "lie on opposite sides of 1.")


def ratios_disagree(s: dict) -> bool:
    """Whether a policy's mean of per-field impulse-per-metre ratios and its
    ratio of means (its summary ``s`` of :func:`summarise_board`) lie on
    opposite sides of 1: one says it meets more ice than the straight
    line, the other less."""
    per_field = (s.get("ratio_impulse_per_metre") or {}).get("mean", math.nan)
    of_means = s.get("ipm_ratio_of_means", math.nan)
    if not (math.isfinite(per_field) and math.isfinite(of_means)):
        return False
    return (per_field - 1.0) * (of_means - 1.0) < 0


def _final(e, key):
    return float(e["final"].get(key, math.nan))


def summarise_board(board: dict, reference: str = "straight") -> dict:
    """Per concentration and policy: mean, std and standard error of the
    return, of every final metric, of the decision time and of the
    per-field ratios to ``reference`` (``ratio_<metric>``), the ratio of
    the means of the impulse per metre (``ipm_ratio_of_means``) and the
    success rate."""
    from .rollouts import compare, stats, summarise

    out = {}
    for a, policies in board.items():
        ref = policies.get(reference)
        out[a] = {}
        for name, episodes in policies.items():
            s = summarise(episodes)
            s["decision_ms"] = stats([e.get("decision_ms", math.nan) for e in episodes])
            if any("plan_ms" in e for e in episodes):
                s["plan_ms"] = stats([e.get("plan_ms", math.nan) for e in episodes])
            s["success_rate"] = float(np.mean([_final(e, "success") > 0 for e in episodes]))
            if ref is not None:
                for key in NORMALISED:
                    r = [_final(e, key) / _final(b, key) if _final(b, key) > 0 else math.nan
                         for e, b in zip(episodes, ref)]
                    s[f"ratio_{key}"] = stats(r)
                mine = np.mean([_final(e, "impulse_per_metre") for e in episodes])
                theirs = np.mean([_final(b, "impulse_per_metre") for b in ref])
                s["ipm_ratio_of_means"] = float(mine / theirs) if theirs > 0 else math.nan
                s["paired_return"] = compare(episodes, ref)
                s["paired_impulse_per_metre"] = compare(episodes, ref, "impulse_per_metre",
                                                        lower_is_better=True)
                paths = np.mean([_final(e, "path_length") for e in episodes])
                s["path_ratio_of_means"] = float(
                    paths / np.mean([_final(b, "path_length") for b in ref]))
            out[a][name] = s
    return out


def pooled_comparison(board: dict, reference: str = "straight") -> dict:
    """Per policy, paired with ``reference`` over the fields of every
    concentration together (the task's spread of concentrations): the
    differences of the return and of the impulse per metre
    (:func:`agents.rollouts.compare`) and the ratios of the means of the
    impulse per metre and of the path. Empty without ``reference``."""
    from .rollouts import compare

    if any(reference not in policies for policies in board.values()):
        return {}
    names = [n for n in next(iter(board.values())) if n != reference
             and all(n in policies for policies in board.values())]
    ref = [e for policies in board.values() for e in policies[reference]]
    out = {}
    for name in names:
        mine = [e for policies in board.values() for e in policies[name]]
        ratio = {key: float(np.mean([_final(e, key) for e in mine])
                            / np.mean([_final(b, key) for b in ref]))
                 for key in ("impulse_per_metre", "path_length")}
        out[name] = dict(
            fields=len(mine), paired_return=compare(mine, ref),
            paired_impulse_per_metre=compare(mine, ref, "impulse_per_metre",
                                             lower_is_better=True),
            ipm_ratio_of_means=ratio["impulse_per_metre"],
            path_ratio_of_means=ratio["path_length"])
    return out


def _paired_cell(c: dict | None, scale: float) -> str:
    if c is None:
        return "–"
    return (_plus_minus(c["diff"] / scale, c["sem"] / scale)
            + (" (beats)" if c["beats"] else ""))


def route_choice_pays(summary: dict, planners) -> dict:
    """``{concentration: (best planner, its impulse-per-metre ratio, its
    path ratio, pays)}``: the planner of ``planners`` with the lowest ratio
    of means among those within the detour limit."""
    verdict = {}
    for a, policies in summary.items():
        rows = [(p, policies[p]["ipm_ratio_of_means"], policies[p]["path_ratio_of_means"])
                for p in planners if p in policies and "ipm_ratio_of_means" in policies[p]]
        fair = [r for r in rows if r[2] <= DETOUR_LIMIT] or rows
        if not fair:
            continue
        best = min(fair, key=lambda r: r[1])
        verdict[a] = (*best, bool(best[1] <= ROUTE_CHOICE_RATIO and best[2] <= DETOUR_LIMIT))
    return verdict


def _pm(s: dict, scale: float = 1.0, digits: int = 3) -> str:
    if not s or not math.isfinite(s.get("mean", math.nan)):
        return "–"
    return _plus_minus(s["mean"] / scale, s["sem"] / scale, digits)


def _plus_minus(value: float, error: float, digits: int = 3) -> str:
    """``value`` to ``digits`` significant figures and ``error`` to two,
    neither with its integer part rounded; an error that is only the
    rounding of floats (:func:`agents.metrics.rounding_noise`: the straight
    line's ratio to itself) as 0."""
    if rounding_noise(value, error):
        error = 0.0
    return f"{significant(value, digits, whole=True)} ± {significant(error, 2, whole=True)}"


def record_commands(report: dict) -> list[str]:
    """The commands that made a record, in order: one per policy
    (``recipes``), else those of its ``command`` (the runs joined by
    "then", as records kept them before the recipes)."""
    recipes = report.get("recipes")
    if isinstance(recipes, dict) and recipes:
        return list(recipes.values())
    return [c.strip() for c in str(report.get("command", "")).split("` then `") if c.strip()]


def recipe_lines(report: dict) -> list[str]:
    """How each policy's rows were made: one command per policy (a record
    merged from several runs names each policy's own), or, for a record
    that kept only its commands, each distinct command once, in order."""
    recipes = report.get("recipes")
    if recipes:
        commits = report.get("commits") or {}
        # policies played by one command at one commit share a row
        rows: dict[tuple, list[str]] = {}
        for name, cmd in recipes.items():
            rows.setdefault((cmd, commits.get(name) or "–"), []).append(name)
        return ["| policies | recipe | commit |", "|---|---|---|",
                *(f"| {', '.join(names)} | `{cmd}` | {commit} |"
                  for (cmd, commit), names in rows.items()), ""]
    commands = list(dict.fromkeys(record_commands(report)))
    return [f"Commands, in order: {'; '.join(f'`{c}`' for c in commands)}.", ""]


def step_text(report: dict) -> str:
    """What a report says of its engine step (a report without the entry
    was made before the fast step became the ship environments' default,
    with the exact step)."""
    step = report.get("step", "exact")
    if step == "fast":
        return "the fast step (`free_drift=True`, the default)"
    if "step" in report:
        return "the exact step (`free_drift=False`)"
    return ("the exact step (`free_drift=False`; made before the fast step became the "
            "ship environments' default)")


def board_markdown(report: dict) -> str:
    """The Markdown of a leaderboard report (the JSON of :func:`main`)."""
    summary = report["summary"]
    lines = [*recipe_lines(report),
             f"Environment `{report['env']}` ({_kwargs_text(report['env_kwargs'])}), "
             f"engine step: {step_text(report)}; "
             f"{report['episodes']} fields per concentration, field k seeded "
             f"{report['seed']} + k, the same fields for every policy; "
             f"{report.get('host', report['machine'])}; {report['date']}; "
             f"{report['wall_s']:.0f} s of wall time.",
             "",
             *_agent_lines(report.get("agent_kwargs") or {}),
             "Means ± standard errors over the fields. Ratios are to the straight line on "
             "the same field (mean of the per-field ratios); *ratio of means* is the mean "
             "impulse per metre over the straight line's.", "",
             RATIO_NOTE, ""]
    verdict = route_choice_pays(summary, report["planners"])
    lines += ["### Does route choice pay?", "",
              f"Route choice pays when the best planner meets at most {ROUTE_CHOICE_RATIO} "
              f"times the straight line's impulse per metre (ratio of means), sailing at most "
              f"{DETOUR_LIMIT - 1:.0%} further.", "",
              "| A | best planner | impulse per metre / straight (ratio of means) | "
              "path / straight | pays |", "|---|---|---|---|---|"]
    for a, (name, ratio, path, pays) in verdict.items():
        lines.append(f"| {a} | {name} | {ratio:.3f} | {path:.3f} | "
                     f"{'yes' if pays else '**no**'} |")
    pooled = report.get("pooled")
    if pooled is None:
        pooled = pooled_comparison(report["episodes_detail"]) if len(summary) > 1 else {}
    if pooled:
        n = next(iter(pooled.values()))["fields"]
        lines += ["", "### All concentrations together", "",
                  f"Each policy paired with the straight line on all {n} fields (policy − "
                  "straight line; *beats*: better by more than two standard errors):", "",
                  "| policy | return − straight's | impulse per metre − straight's [kN s/m] "
                  "| impulse per metre, ratio of means | path, ratio of means |",
                  "|---|---|---|---|---|"]
        for name, c in pooled.items():
            lines.append(f"| {name} | {_paired_cell(c['paired_return'], 1.0)} | "
                         f"{_paired_cell(c['paired_impulse_per_metre'], 1e3)} | "
                         f"{c['ipm_ratio_of_means']:.3f} | {c['path_ratio_of_means']:.3f} |")
    for a, policies in summary.items():
        lines += ["", f"### A = {a}", "",
                  "| policy | return | success | " + " | ".join(
                      f"{h} [{u}]" if u else h for _, h, _, u in SHOWN)
                  + " | decision [ms] |",
                  "|---" * (len(SHOWN) + 4) + "|"]
        for name, s in policies.items():
            cells = [name, _pm(s["return"], 1.0, 4), f"{s['success_rate']:.0%}"]
            cells += [_pm(s.get(key), scale) for key, _, scale, _ in SHOWN]
            cells.append(_pm(s["decision_ms"], 1.0, 2))
            lines.append("| " + " | ".join(cells) + " |")
        lines += ["", "Normalised by the straight line on the same field, and the paired "
                  "differences (policy − straight line; *beats*: better by more than two "
                  "standard errors):", "",
                  "| policy | " + " | ".join(NORMALISED) + " | impulse per metre, ratio of means "
                  "| return − straight's | impulse per metre − straight's [kN s/m] "
                  "| plan [ms] |", "|---" * (len(NORMALISED) + 5) + "|"]
        for name, s in policies.items():
            cells = [name] + [_pm(s.get(f"ratio_{k}"), 1.0, 3) for k in NORMALISED]
            of_means = s.get("ipm_ratio_of_means", math.nan)
            cells.append(f"{of_means:.3f}" + (" †" if ratios_disagree(s) else ""))
            for key, scale in (("paired_return", 1.0), ("paired_impulse_per_metre", 1e3)):
                cells.append(_paired_cell(None if name == "straight" else s.get(key), scale))
            cells.append(_pm(s.get("plan_ms"), 1.0, 2))
            lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


def _agent_lines(agent_kwargs: dict) -> list[str]:
    """The trained runs that act or observe otherwise than the environment's
    defaults (:data:`agents.rollouts.AGENT_KWARGS`)."""
    if not agent_kwargs:
        return []
    return ["Trained runs act and observe as they were trained, on the same task: " + "; ".join(
        f"{name} with {_kwargs_text(kw)}" for name, kw in agent_kwargs.items()) + ".", ""]


def _kwargs_text(kwargs: dict) -> str:
    return ", ".join(f"{k}={v!r}" for k, v in kwargs.items()) or "defaults"


def plot_board(report: dict, path: Path) -> None:
    """Impulse per metre over the straight line's, and the return, against
    the concentration, per policy, with standard errors."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from physics.scenarios.plots import to_palette

    summary = report["summary"]
    conc = [float(a) for a in summary]
    names = list(next(iter(summary.values())))
    fig, (ax0, ax1) = plt.subplots(1, 2, figsize=(10, 4))
    for name in names:
        rows = [summary[a][name] for a in summary]
        ax0.errorbar(conc, [r["ratio_impulse_per_metre"]["mean"] for r in rows],
                     [r["ratio_impulse_per_metre"]["sem"] for r in rows], marker="o",
                     capsize=3, label=name)
        ax1.errorbar(conc, [r["return"]["mean"] for r in rows],
                     [r["return"]["sem"] for r in rows], marker="o", capsize=3, label=name)
    ax0.axhline(ROUTE_CHOICE_RATIO, color="grey", ls="--", lw=1,
                label=f"{ROUTE_CHOICE_RATIO} × straight")
    ax0.set(xlabel="ice concentration A", ylabel="impulse per metre / straight line's",
            title="ice met, per field, over the straight line's")
    ax1.set(xlabel="ice concentration A", ylabel="return", title="return")
    ax0.legend(fontsize=8)
    fig.suptitle(f"{report['env']}: {report['episodes']} paired fields per concentration")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    to_palette(path)


def default_policies(env_id: str) -> list[str]:
    """The baselines a leaderboard of ``env_id`` runs by default: the
    straight line, the environment's other controllers and the planners
    of :mod:`agents.planners` (not the generic ones, nor ``heuristic``,
    another name of ``reactive``, nor the planners played only when named,
    :data:`agents.planners.ON_REQUEST`)."""
    from .baselines import GENERIC, baseline_names
    from .planners import ON_REQUEST

    return [n for n in baseline_names(env_id)
            if n not in GENERIC and n != "heuristic" and n not in ON_REQUEST]


#: what :func:`agents.rollouts.run_episode` counts of a ship's steps, where it can
EPISODE_COUNTS = ("outside_steps", "guard_overrides")


def _counts(episodes: list[dict]) -> list[str]:
    """The mean steps outside the channel per field, and the share of steps
    on which the course guard overrode the command ("–" where not counted)."""
    cells = []
    for key in EPISODE_COUNTS:
        if not episodes or not all(key in e for e in episodes):
            cells.append("–")
        elif key == "outside_steps":
            cells.append(f"{np.mean([e[key] for e in episodes]):.1f}")
        else:
            share = sum(e[key] for e in episodes) / max(sum(e["length"] for e in episodes), 1)
            cells.append(f"{share:.1%}")
    return cells


def grouped(board: dict, groups: dict) -> dict:
    """``board`` with a policy for each group (name → its member policies,
    e.g. one trained run's seeds): on each field the mean of its members'
    returns, so that a learner's seeds are compared as one policy, paired
    by field. Members missing from the board are an error."""
    out = {}
    for a, policies in board.items():
        out[a] = dict(policies)
        for name, members in groups.items():
            missing = [m for m in members if m not in policies]
            if missing:
                raise ValueError(f"group {name}: {', '.join(missing)} not on the board "
                                 f"(policies: {', '.join(policies)})")
            rows = [policies[m] for m in members]
            out[a][name] = [{"seed": e[0]["seed"], "final": {},
                             **{key: _mean_of_members([x[key] for x in e])
                                for key in ("ret", "length", *EPISODE_COUNTS)
                                if all(key in x for x in e)}} for e in zip(*rows)]
    return out


def _mean_of_members(values) -> float:
    """The mean of ``values`` as the first plus the mean of the others'
    differences from it: members that sailed alike give their own return
    exactly, so that a group of them paired with one of them shows 0 ± 0,
    not the rounding of a sum (mean(a, a, a) need not be a in floats)."""
    first = float(values[0])
    return first + float(np.mean([float(v) - first for v in values]))


def against_markdown(board: dict, reference: str, groups: dict | None = None) -> str:
    """A table of every policy's return paired with ``reference``'s on the
    same fields (policy − reference, mean ± standard error; *beats* /
    *loses*: by more than two standard errors), at each concentration and
    over all together; groups (:func:`grouped`) as policies of their own."""
    from .rollouts import compare

    board = grouped(board, groups or {})
    concentrations = list(board)
    if reference not in board[concentrations[0]]:
        raise ValueError(f"--against {reference}: not on the board "
                         f"(policies: {', '.join(board[concentrations[0]])})")
    names = [n for n in board[concentrations[0]] if n != reference]
    lines = [f"Return − {reference}'s on the same fields (mean ± standard error over the "
             f"fields; *beats* / *loses*: by more than two standard errors"
             + ("; a group's return on a field is the mean of its members': "
                + "; ".join(f"{g} = {', '.join(m)}" for g, m in groups.items())
                if groups else "") + "):", "",
             "| policy | " + " | ".join(f"A = {a}" for a in concentrations)
             + " | all | steps outside the channel (per field) | guard overrides (of steps) |",
             "|---" * (len(concentrations) + 4) + "|"]
    for name in names:
        cells = []
        for a in concentrations:
            c = compare(board[a][name], board[a][reference])
            cells.append(_paired_cell(c, 1.0).replace(" (beats)", " beats")
                         + (" loses" if c["loses"] else ""))
        every = compare([e for a in concentrations for e in board[a][name]],
                        [e for a in concentrations for e in board[a][reference]])
        cells.append(_paired_cell(every, 1.0).replace(" (beats)", " beats")
                     + (" loses" if every["loses"] else ""))
        cells += _counts([e for a in concentrations for e in board[a][name]])
        lines.append(f"| {name} | " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


def _group_argument(item: str) -> tuple[str, list[str]]:
    name, sep, members = item.partition("=")
    if not sep or not name or not members:
        raise argparse.ArgumentTypeError(f"a group is NAME=POLICY,POLICY,..., got {item!r}")
    return name, [m for m in members.split(",") if m]


def policy_label(item: str) -> tuple[str, str]:
    """(the board's name, the policy) of a ``--policies`` item: ``NAME=module:Class...``
    names a policy of one's own NAME; any other item is its own name.

    >>> policy_label("student-s1=agents.waypoints:WaypointStudent?run=runs/s1")
    ('student-s1', 'agents.waypoints:WaypointStudent?run=runs/s1')
    >>> policy_label("agents.baselines:ZeroPolicy?gain=1")
    ('agents.baselines:ZeroPolicy?gain=1', 'agents.baselines:ZeroPolicy?gain=1')
    """
    from .policy import is_reference

    label, sep, rest = item.partition("=")
    if sep and label and not any(c in label for c in ":?/") and is_reference(rest):
        if "." in label:
            raise ValueError(f"the name {label!r} of {item!r} holds a '.', which would read "
                             f"as a module's path: name it without one (e.g. "
                             f"{label.replace('.', '')!r})")
        return label, rest
    return item, item


def build_parser(prog: str = "python -m agents.leaderboard") -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog=prog, description=__doc__.split("\n\n")[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--env", default=DEFAULT_ENV, help=f"ship environment id ({DEFAULT_ENV})")
    p.add_argument("--concentrations", default="0.2,0.3,0.4,0.5",
                   help="comma-separated ice concentrations (0.2,0.3,0.4,0.5)")
    p.add_argument("--episodes", type=int, default=20, help="fields per concentration (20)")
    p.add_argument("--seed", type=int, default=10_000, help="seed of field 0 (10000)")
    p.add_argument("--policies", default=None,
                   help="comma-separated baselines (default: the environment's planners, "
                        "such as straight,reactive,swath,lattice on ShipNavigation-v1) and "
                        "policies of one's own, module:Class or path/to/file.py:Class "
                        "(?key=value&... for their arguments, YAML values; a comma inside "
                        "brackets, as in ?offsets=[-4,4], is the value's; agents.policy), each "
                        "NAME=module:Class... to show it as NAME")
    p.add_argument("--trained", action="append", default=[], metavar="NAME=RUN_DIR[@STEPS]",
                   help="a trained policy (agents.train's run directory; @STEPS: its checkpoint "
                        "at STEPS steps), repeatable")
    p.add_argument("--env-kwargs", nargs="*", default=[], metavar="KEY=VALUE",
                   help="gymnasium.make keywords (YAML values)")
    p.add_argument("--processes", type=int, default=2, help="worker processes (2)")
    p.add_argument("--out", type=Path, default=DEFAULT_OUT,
                   help=f"output directory (default {DEFAULT_OUT})")
    p.add_argument("--render", action="store_true",
                   help="write the table and the plot again from the JSON in --out (and the "
                        "JSON, its summaries to 8 significant figures)")
    p.add_argument("--merge", action="store_true",
                   help="keep the policies of the JSON in --out (same environment, arguments, "
                        "concentrations and fields) and run only the others")
    p.add_argument("--against", default="", metavar="NAMES",
                   help="with --render: for each comma-separated policy NAME, write "
                        "against-NAME.md, every policy's return paired with NAME's")
    p.add_argument("--group", action="append", default=[], type=_group_argument,
                   metavar="NAME=POLICY,POLICY,...",
                   help="with --against: a policy whose return on a field is the mean of "
                        "its members' (a trained run's seeds), repeatable")
    p.add_argument("--replace", default="", metavar="NAMES",
                   help="with --merge: comma-separated policies to run again and replace "
                        "though the JSON has them")
    return p


def _write(report: dict, out: Path) -> None:
    (out / "leaderboard.md").write_text(board_markdown(report))
    plot_board(report, out / "leaderboard.png")


def read_board(out: Path) -> tuple[dict, dict | None]:
    """The record of ``out`` and the episodes behind it (``None`` when they
    are not there, as for a committed record). A record written before the
    two were split holds its episodes itself (``episodes_detail``)."""
    report = json.loads((Path(out) / RECORD).read_text())
    episodes = report.pop("episodes_detail", None)
    path = Path(out) / EPISODES
    if path.exists():
        episodes = json.loads(path.read_text())
    return report, episodes


#: significant figures a record keeps of its summaries (its tables show at most
#: four); the episodes behind them keep every digit
RECORD_DIGITS = 8


def rounded(value):
    """``value`` with every float in it to :data:`RECORD_DIGITS` significant
    figures (dicts and lists gone through)."""
    if isinstance(value, float):
        return float(f"{value:.{RECORD_DIGITS}g}") if math.isfinite(value) else value
    if isinstance(value, dict):
        return {k: rounded(v) for k, v in value.items()}
    if isinstance(value, list):
        return [rounded(v) for v in value]
    return value


def summarised(report: dict, board: dict) -> dict:
    """``report`` with the summaries and the pooled comparison of ``board``
    (:func:`rounded`)."""
    summary = summarise_board(board)
    return {**report, "summary": rounded(summary),
            "pooled": rounded(pooled_comparison(board)) if len(summary) > 1 else {}}


def _mergeable(parser, args, out: Path, conc, env_kwargs, again) -> dict:
    """The report in ``out`` that ``--merge`` adds to, checked to be of the
    same environment, arguments, fields and concentrations, and, unless
    every policy of it runs again (``again``), of the same host
    (:func:`host_signature`)."""
    path = out / RECORD
    if not path.exists():
        parser.error(f"--merge: {path} does not exist")
    old, episodes = read_board(out)
    same = (old.get("env") == args.env and old.get("env_kwargs") == env_kwargs
            and old.get("episodes") == args.episodes and old.get("seed") == args.seed
            and list(old.get("summary", {})) == [f"{a:g}" for a in conc])
    if not same:
        parser.error(f"--merge: {path} is of another environment, arguments, fields or "
                     f"concentrations")
    from iceenvs.checks import engine_step

    step = engine_step(args.env, env_kwargs)
    if step is not None and old.get("step", "exact") != step:
        parser.error(f"--merge: {path} was made with {step_text(old)}, this run would use "
                     f"the {step} step, and their episodes would not pair: make a new board "
                     f"(without --merge)")
    kept = set(next(iter(old["summary"].values()))) - set(again)
    if kept and episodes is None:
        parser.error(f"--merge: the episodes behind {path} are not in {out} ({EPISODES}, "
                     f"which a committed record leaves out); run all of its policies again "
                     f"(--replace {','.join(sorted(kept))})")
    old["episodes_detail"] = episodes or {}
    host = host_signature()
    if kept and old.get("host") != host:
        parser.error(f"--merge: {path} was computed on another host "
                     f"({old.get('host', 'not recorded')}; this one: {host}). Its "
                     f"episodes start from the same fields but do not follow the same "
                     f"trajectories here, so they would not pair with new ones: run all of its "
                     f"policies again (--replace {','.join(sorted(kept))}) or write elsewhere "
                     f"(--out)")
    return old


def main(argv: list[str] | None = None, prog: str = "python -m agents.leaderboard") -> dict:
    parser = build_parser(prog)
    args = parser.parse_args(argv)
    out = args.out
    if args.render:
        path = out / RECORD
        if not path.exists():
            parser.error(f"--render: {path} does not exist")
        report, episodes = read_board(out)
        if episodes is not None:            # summarised again, with this version's statistics
            if not (out / EPISODES).exists():   # a record that held its episodes keeps them
                (out / EPISODES).write_text(json.dumps(episodes))
            report = summarised(report, episodes)
        else:
            report = {**report, "summary": rounded(report["summary"])}
            if report.get("pooled") is not None:
                report["pooled"] = rounded(report["pooled"])
        (out / RECORD).write_text(json.dumps(report))
        _write(report, out)
        against = [n for n in args.against.split(",") if n]
        if against and episodes is None:
            parser.error(f"--against pairs episodes, and {out / EPISODES} does not exist")
        for name in against:
            try:
                text = against_markdown(episodes, name, dict(args.group))
            except ValueError as err:
                parser.error(str(err))
            (out / f"against-{name}.md").write_text(text)
        return report

    import numba

    from iceenvs.checks import engine_step

    from .baselines import check_policy_names
    from .envs import make_checked_env, parse_key_values
    from .planners import PLANNERS
    from .policy import is_reference, split_policies
    from .rollouts import policy_recipe, run_agent_kwargs, trained_argument

    if args.episodes < 2:
        parser.error("--episodes must be at least 2 (standard errors)")
    if args.processes < 1:
        parser.error("--processes must be at least 1")
    try:
        conc = [float(a) for a in args.concentrations.split(",") if a.strip()]
        env_kwargs = parse_key_values(args.env_kwargs)
    except ValueError as err:
        parser.error(str(err))
    if not conc:
        parser.error("--concentrations is empty")
    if "concentration" in env_kwargs:
        parser.error("--env-kwargs concentration: the concentrations come from --concentrations")
    try:
        policies = (split_policies(args.policies) if args.policies is not None
                    else default_policies(args.env))
    except ValueError as err:
        parser.error(f"--policies: {err}")
    try:
        named = dict(policy_label(p) for p in policies)
    except ValueError as err:
        parser.error(f"--policies: {err}")
    if len(named) < len(policies):
        parser.error("--policies names a policy twice")
    try:
        check_policy_names(list(named.values()), args.env)
    except ValueError as err:
        parser.error(str(err))
    if "straight" not in named:
        named = {"straight": "straight", **named}
    try:
        recipes = {label: policy_recipe(name) for label, name in named.items()}
    except ValueError as err:
        parser.error(str(err))
    for item in args.trained:
        try:
            name, run_dir, steps = trained_argument(item, args.env)
        except ValueError as err:
            parser.error(str(err))
        recipes[name] = ("trained", run_dir, {} if steps is None else {"checkpoint": steps})
    for a in conc:
        try:
            make_checked_env(args.env, {**env_kwargs, "concentration": a}).close()
        except (TypeError, ValueError) as err:
            print(f"{prog}: error: {args.env} with concentration {a:g}: {err}", file=sys.stderr)
            raise SystemExit(2) from None
    again = [n.strip() for n in args.replace.split(",") if n.strip()]
    if again and not args.merge:
        parser.error("--replace needs --merge")
    for name in again:
        if name not in recipes:
            parser.error(f"--replace {name}: not among the policies of this run")
    old = _mergeable(parser, args, out, conc, env_kwargs, again) if args.merge else None
    out.mkdir(parents=True, exist_ok=True)
    if old is not None:
        recipes = {name: r for name, r in recipes.items()
                   if name in again or name not in next(iter(old["summary"].values()))}
    agent_kwargs = {**(old or {}).get("agent_kwargs", {}), **{
        name: run_agent_kwargs(r[1]) for name, r in recipes.items() if r[0] == "trained"}}
    planner_names = {*PLANNERS, *default_policies(args.env)}
    t0 = time.perf_counter()
    board = run_leaderboard(args.env, conc, recipes, episodes=args.episodes, seed=args.seed,
                            processes=args.processes, env_kwargs=env_kwargs)
    argv_text = " ".join(shlex.quote(a) for a in (sys.argv[1:] if argv is None else argv))
    command = f"{prog} {argv_text}".strip()
    commit = source_commit()
    played = {name: command for name in recipes}
    commits = {name: commit for name in recipes}
    if old is not None:
        board = {a: {**old["episodes_detail"][a], **board[a]} for a in board}
        names = list(board[next(iter(board))])
        before = old.get("recipes") or {n: old["command"] for n in old["summary"][f"{conc[0]:g}"]}
        played = {name: played.get(name) or before[name] for name in names}
        commits = {name: commits[name] if name in commits else
                   (old.get("commits") or {}).get(name, old.get("commit")) for name in names}
        recipes = {name: None for name in names}
    report = dict(
        recipes=played, commits=commits, commit=commit,
        env=args.env, env_kwargs=env_kwargs, step=engine_step(args.env, env_kwargs),
        agent_kwargs={name: kw for name, kw in agent_kwargs.items() if kw and name in recipes},
        episodes=args.episodes, seed=args.seed,
        planners=[p for p in recipes if p != "straight" and p in planner_names],
        own_policies=[p for p in recipes if is_reference(named.get(p, p))
                      or p in (old or {}).get("own_policies", ())],
        machine=f"{platform.machine()}, {platform.system()}, numba {numba.__version__}",
        host=host_signature(),
        date=datetime.date.today().isoformat(),
        wall_s=time.perf_counter() - t0 + (old["wall_s"] if old else 0.0))
    episodes = {a: {name: [{k: v for k, v in e.items() if k not in ("rewards", "trace")}
                           for e in eps] for name, eps in policies_.items()}
                for a, policies_ in board.items()}
    report = summarised(report, episodes)
    (out / RECORD).write_text(json.dumps(report))
    (out / EPISODES).write_text(json.dumps(episodes))
    _write(report, out)
    print(board_markdown(report))
    return {**report, "episodes_detail": episodes}


if __name__ == "__main__":
    main()
