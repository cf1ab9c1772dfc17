"""The evaluation table of agents.evaluate: every metric with a header and
its unit, cells in significant figures, the task parameters drawn per
episode recorded and reported, the leaderboard's fields reproduced with
``--env-kwargs concentration=A``, and the target on the evaluation plot."""
import doctest
import json
import math
import re

import gymnasium as gym
import numpy as np
import pytest

import agents.metrics
import iceenvs.ship_env
import iceenvs.thickness_distribution
from agents.evaluate import markdown_table, table_columns
from agents.metrics import (METRIC_UNITS, format_pm, logged_names, metric_header, scaled,
                            significant)
from iceenvs import ENV_IDS
from iceenvs.facts import env_facts
from small_envs import SMALL

pytest.importorskip("stable_baselines3")

CONVERGENCE = "iceenvs/Convergence-v0"
SHIP = "iceenvs/ShipNavigation-v1"
# a short crossing of ShipNavigation-v1 (as the leaderboard's tests sail)
SHORT_SHIP = {"goal_distance": 200.0, "length": 500.0}
#: display unit → (SI unit, its size in SI)
PREFIXED = {"kN s/m": ("N s/m", 1e3), "kN s": ("N s", 1e3), "MN s": ("N s", 1e6),
            "MJ": ("J", 1e6), "kN": ("N", 1e3), "kN/m": ("N/m", 1e3), "t": ("kg", 1e3),
            "mm²/s²": ("m²/s²", 1e-6), "%": ("", 1e-2)}


def test_the_module_examples_hold():
    assert doctest.testmod(agents.metrics).failed == 0


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_every_logged_metric_has_a_header_and_unit(env_id):
    names = logged_names(env_id)
    assert names, f"{env_id} logs every scalar entry: its names are not known in advance"
    missing = [n for n in names if n not in METRIC_UNITS]
    assert not missing, (f"{env_id} logs {missing} without a header and unit in "
                         f"agents.metrics.METRIC_UNITS")


def test_display_units_are_the_si_units_scaled():
    for name, (header, unit, scale, si) in METRIC_UNITS.items():
        assert header and scale > 0, name
        if unit == si:
            assert scale == 1.0, name
        else:
            assert PREFIXED[unit] == (si, scale), name
        assert metric_header(name) == (f"{header} [{unit}]" if unit else header)
    # a metric not in the table keeps its name and its SI value
    assert metric_header("no_such_metric") == "no_such_metric"
    assert scaled("no_such_metric", 2.5e8) == 2.5e8
    assert scaled("impulse_per_metre", 19950.0) == pytest.approx(19.95)


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_si_units_are_those_the_environment_documents(env_id):
    """The SI unit of each metric is the one of the environment's observation
    feature of that entry, or the one the ship environments' and the
    thickness distribution's docstrings give."""
    documented = {}
    for doc in (iceenvs.ship_env.__doc__,
                iceenvs.thickness_distribution.ThicknessDistributionEnv.__doc__):
        text = " ".join(doc.split())
        for a, b, unit in re.findall(r"`+(\w+)`+(?: and `+(\w+)`+)? \[([^\]]+)\]", text):
            documented.update({a: unit, **({b: unit} if b else {})})
        # ... and "`w1` (the Wasserstein-1 distance to the target [m])"
        documented.update(re.findall(r"`+(\w+)`+ \([^()]*?\[([^\]]+)\]\)", text))
    env = gym.make(env_id, **SMALL[env_id])
    features = {f.name: f.unit for f in getattr(env.unwrapped, "features", ())}
    env.close()
    facts = env_facts(env_id)
    checked = 0
    for key, name in [*facts.metrics.items(), *((n, n) for n in facts.episode_metrics)]:
        unit = features.get(key, documented.get(key))
        if unit is None:
            continue
        assert METRIC_UNITS[name].si == ("" if unit == "-" else unit), (env_id, name, unit)
        checked += 1
    assert checked >= len(facts.metrics) // 2


def test_the_leaderboard_shows_its_metrics_in_the_same_units():
    from agents.leaderboard import SHOWN

    assert [row[0] for row in SHOWN][:2] == ["impulse_per_metre", "energy_to_ice"]
    for name, header, scale, unit in SHOWN:
        assert METRIC_UNITS[name][:3] == (header, unit, scale), name
    assert ("impulse_per_metre", "ice impulse per metre", 1e3, "kN s/m") in SHOWN


def test_cells_have_significant_figures_and_no_exponent():
    assert format_pm(143.62, 2.08) == "143.6 ± 2.1"
    assert format_pm(97.22, 37.0) == "97.2 ± 37"
    assert format_pm(0.78813, 0.0048) == "0.7881 ± 0.0048"
    assert format_pm(2.186e8, 0.0) == "219000000 ± 0"
    assert format_pm(51.0, 0.0) == "51 ± 0" and format_pm(0.5, 0.0) == "0.500 ± 0"
    assert format_pm(-1e-9, 2.0) == "0.000 ± 2.0"             # never "-0"
    assert format_pm(math.nan, 1.0) == "–"
    assert significant(0.0001234) == "0.000123"
    rng = np.random.default_rng(1)
    for mean, error in zip(rng.choice([-1, 1], 500) * 10.0 ** rng.uniform(-7, 9, 500),
                           10.0 ** rng.uniform(-7, 9, 500)):
        text = format_pm(mean, error)
        assert "e" not in text.lower(), text
        shown_mean, shown_error = (float(x) for x in text.split(" ± "))
        if error <= 1e-9 * abs(mean):          # the rounding of floats, not a spread
            assert shown_error == 0, text
            continue
        assert shown_error == pytest.approx(error, rel=0.05)
        # three significant figures, or to the error's last decimal and two more
        assert abs(shown_mean - mean) <= max(5e-3 * abs(mean), 0.01 * error) * 1.0001, text


def _summary(mean, sem):
    return dict(mean=mean, std=sem * math.sqrt(2), sem=sem, n=2)


def test_ship_table_shows_units_and_splits_the_metrics():
    facts = env_facts(SHIP)
    keys = ["return", "length", *logged_names(SHIP)]
    summary = {k: _summary(1.0, 0.1) for k in keys}
    summary["impulse_per_metre"] = _summary(19960.0, 2100.0)
    summary["effort"] = _summary(2.186e8, 1.2e7)
    summary["success"] = _summary(0.5, 0.5)
    summary["unlisted_metric"] = _summary(2.5e8, 1e7)
    comparisons = {"straight": dict(diff=-12.34, sem=4.1, beats=False, loses=True)}
    metric = {"straight": dict(diff=-3210.0, sem=830.0, beats=True)}
    task = dict(drawn={"concentration": dict(min=0.213, max=0.478, range=[0.2, 0.5])},
                fixed={"wind_speed": 5.0}, leaderboard=True)
    text = markdown_table(SHIP, {"mine": summary, "straight": summary}, comparisons, 2,
                          10_000, {"mine": "my policy"}, metric, task)
    assert "e+" not in text and "e-0" not in text
    main, second = text.split("The other final metrics")
    assert "| policy | return | success [%] | ice impulse per metre [kN s/m] |" in main
    assert "| my policy | 1.00 ± 0.10 | 50.0 ± 50 | 20.0 ± 2.1 |" in main
    assert main.count("|---") == len(table_columns(SHIP, summary)[0]) + 1
    assert "| metric | my policy | straight |" in second
    assert "| effort (work of the thrust, or against ice and water) [MJ] | 219 ± 12 |" in second
    assert "| unlisted_metric | 250000000 ± 10000000 |" in second
    assert "mean ± the standard error of the mean" in main
    assert ("ice concentration 0.213 to 0.478 (drawn from 0.2 to 0.5)" in text
            and "seeded 10000 + k" in text)
    assert "fixed for every episode by the environment arguments: wind_speed = 5" in text.lower()
    assert "`--env-kwargs concentration=A`" in text
    assert "| straight | -12.3 ± 4.1 | loses |" in text
    assert (f"| baseline | difference of the {metric_header(facts.compared_metric[0])} |"
            in text)
    assert "| straight | -3.21 ± 0.83 | beats |" in text


def test_run_episode_records_the_drawn_task():
    from agents.baselines import make_baseline
    from agents.rollouts import run_episode

    env = gym.make(CONVERGENCE, **SMALL[CONVERGENCE], max_episode_steps=2)
    zero = make_baseline("zero", env, seed=0)
    a, b = (run_episode(env, zero, seed, "concentration") for seed in (5, 6))
    assert set(a["task"]) == {"target", "concentration"}
    assert all(type(v) is float for v in a["task"].values())
    assert a["task"] != b["task"]
    assert 0.75 <= a["task"]["target"] <= 0.84 and 0.70 <= a["task"]["concentration"] <= 0.80
    assert a["task"] == run_episode(env, zero, 5, "concentration")["task"]
    json.dumps(a["task"], allow_nan=False)
    env.close()
    # a parameter the arguments fix is not drawn
    env = gym.make(CONVERGENCE, **SMALL[CONVERGENCE], max_episode_steps=2, target=0.8)
    fixed = run_episode(env, make_baseline("zero", env, seed=0), 5, "concentration")
    assert set(fixed["task"]) == {"concentration"}
    assert fixed["task"]["concentration"] == a["task"]["concentration"]
    env.close()


def test_evaluation_reports_the_drawn_and_fixed_task_and_plots_the_targets(tmp_path,
                                                                             monkeypatch):
    from agents.evaluate import main as evaluate_main
    from physics.scenarios import plots

    figures = []
    monkeypatch.setattr(plots, "savefig", lambda fig, path, **kw: figures.append(fig))
    kwargs = ["n_floes=60", "max_episode_steps=4"]
    evaluate_main(["--baseline", "heuristic", "--env", CONVERGENCE, "--episodes", "3",
                   "--no-progress", "--out", str(tmp_path / "a"), "--env-kwargs", *kwargs])
    report = json.loads((tmp_path / "a" / "evaluation.json").read_text())
    assert "episodes_detail" not in report
    episodes = json.loads((tmp_path / "a" / "episodes.json").read_text())["heuristic"]
    targets = [e["task"]["target"] for e in episodes]
    assert len(set(targets)) == 3 and [e["final"]["target"] for e in episodes] == targets
    assert report["task"]["drawn"]["target"]["min"] == min(targets)
    table = (tmp_path / "a" / "evaluation.md").read_text()
    def short(x):
        return significant(x).rstrip("0").rstrip(".")

    assert f"target {short(min(targets))} to {short(max(targets))} (drawn from" in table
    assert "drawn per episode" in table and "leaderboard" not in table
    assert "| policy | return | ice concentration | target |" in table
    # the plot: the main metric with its header, a dashed target per episode
    ax = figures[0].axes[1]
    assert ax.get_ylabel() == metric_header("concentration")
    assert [t.get_text() for t in ax.get_legend().get_texts()] == ["target (drawn per episode)"]
    dashed = [c for c in ax.collections if c.get_linestyle()[0][1] is not None]
    assert sorted(seg[0][1] for c in dashed for seg in c.get_segments()) == sorted(targets)

    # the table again from the record alone: the same text
    (tmp_path / "a" / "evaluation.md").unlink()
    evaluate_main(["--render", str(tmp_path / "a")])
    assert (tmp_path / "a" / "evaluation.md").read_text() == table
    with pytest.raises(SystemExit):
        evaluate_main(["--render", str(tmp_path / "nothing")])

    evaluate_main(["--baseline", "heuristic", "--env", CONVERGENCE, "--episodes", "2",
                   "--no-progress", "--out", str(tmp_path / "b"), "--env-kwargs", *kwargs,
                   "target=0.8"])
    table = (tmp_path / "b" / "evaluation.md").read_text()
    assert "by the environment arguments: target = 0.8." in table
    report = json.loads((tmp_path / "b" / "evaluation.json").read_text())
    assert list(report["task"]["drawn"]) == ["concentration"]
    legend = figures[-1].axes[1].get_legend()
    assert [t.get_text() for t in legend.get_texts()] == ["target"]
    for fig in figures:
        plots.pyplot().close(fig)


def test_a_fixed_concentration_plays_the_leaderboards_fields(tmp_path):
    """``--env-kwargs concentration=A`` with the default seed plays field k of
    the leaderboard's row A as episode k: the same final metrics."""
    from agents.evaluate import main as evaluate_main
    from agents.leaderboard import run_leaderboard

    args = [f"{k}={v}" for k, v in SHORT_SHIP.items()]
    evaluate_main(["--baseline", "straight", "--env", SHIP, "--episodes", "1", "--no-progress",
                   "--out", str(tmp_path), "--env-kwargs", *args, "concentration=0.3"])
    mine = json.loads((tmp_path / "episodes.json").read_text())["straight"]
    board = run_leaderboard(SHIP, [0.3], {"straight": ("baseline", "straight", {})},
                            episodes=1, seed=10_000, processes=1, env_kwargs=SHORT_SHIP,
                            progress=False)
    field = board["0.3"]["straight"][0]
    assert mine[0]["seed"] == field["seed"] == 10_000
    assert field["final"]["collisions"] > 0          # the field holds ice on the way
    assert mine[0]["final"] == pytest.approx(field["final"], rel=1e-9, abs=1e-12)
    assert mine[0]["task"] == field["task"]
    assert "concentration" not in mine[0]["task"]     # fixed, not drawn
    table = (tmp_path / "evaluation.md").read_text()
    assert "concentration = 0.3" in table
    assert ("These episodes are its field 0 at A = 0.3 of a leaderboard run with "
            "`--env-kwargs goal_distance=200.0 length=500.0`." in table)


def test_significant_keeps_the_integer_part_when_asked_to():
    from agents.metrics import significant

    assert significant(1234.5, 3) == "1230"
    assert significant(1234.5, 3, whole=True) == "1234"
    assert significant(0.012345, 3, whole=True) == "0.0123"
    assert significant(-98.76, 2, whole=True) == "-99"
