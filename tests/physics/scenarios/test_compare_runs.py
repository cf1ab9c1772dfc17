"""``ice-scenarios compare``: two runs of a scenario side by side, the
ensemble means against the spread of the members."""
from __future__ import annotations

import math

import numpy as np
import pytest

pytest.importorskip("xarray")
pytest.importorskip("yaml")

from physics.scenarios import cli, run_scenario
from physics.scenarios.compare import Row, compare_runs

WIND = dict(floes=100, concentrations=[0.6, 0.8], duration=20.0, output_interval=2.0,
            snapshot_times=[10.0])
QUIET = dict(progress=False, plots=False, log=lambda *a: None, workers=1)


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    """Two 2-member wind ensembles with different seeds, and a third run of
    another scenario."""
    root = tmp_path_factory.mktemp("compare")
    a = run_scenario("herman2013-wind", overrides=WIND, ensemble=2, seed=1, out=root / "a",
                     **QUIET)
    b = run_scenario("herman2013-wind", overrides=WIND, ensemble=2, seed=2, out=root / "b",
                     **QUIET)
    c = run_scenario("herman2013-convergence", overrides=dict(
        floes=200, start_concentration=0.84, end_concentration=0.88, rate=2.0,
        output_step=0.004), out=root / "c", **QUIET)
    return a.directory, b.directory, c.directory


def test_the_spread_and_the_verdict():
    row = Row("A = 0.8", "p", np.array([1.0, 3.0]), np.array([4.0, 6.0]))
    # σ = √(2 + 2) = 2, difference 3: 1.5 σ
    assert row.spread == pytest.approx(2.0) and row.difference == pytest.approx(3.0)
    assert row.within(2.0) is True and row.within(1.0) is False
    single = Row("A = 0.8", "p", np.array([1.0, 3.0]), np.array([6.0]))
    assert single.spread == pytest.approx(math.sqrt(2.0)) and single.within(2.0) is False
    assert Row("x", "p", np.array([1.0]), np.array([2.0])).within(2.0) is None


def test_a_run_against_itself_and_against_other_seeds(runs):
    a, b, _ = runs
    same = compare_runs(a, a)
    assert same.basis.startswith("time means over the second half")
    assert {r.case for r in same.rows} == {"concentration = 0.6", "concentration = 0.8"}
    assert {"p", "tau", "z_c", "z_a"} <= {r.quantity for r in same.rows}
    assert "time" not in {r.quantity for r in same.rows}
    assert all(r.difference == 0.0 for r in same.rows if r.reference.size)
    assert not same.outside and not same.differences

    other = compare_runs(a, b, quantities=["p", "z_c"])
    assert [r.quantity for r in other.rows] == ["p", "z_c", "p", "z_c"]
    assert "seed: 1 / 2" in other.differences
    # the means are those of the members' second halves, recomputed here
    import xarray as xr
    with xr.open_dataset(a / "results.nc", engine="h5netcdf") as ds:
        t, p = ds["time"].values[1], ds["p"].values[1]
    half = t >= 0.5 * t.max(axis=-1, keepdims=True)
    expected = [np.mean(p[m][half[m]]) for m in range(2)]
    np.testing.assert_allclose(other.rows[2].reference, expected, rtol=1e-12)
    ratio = compare_runs(a, a, quantities=["p", "tau", "p/tau"])
    p, tau, p_tau = (ratio.rows[3 + k].reference for k in range(3))
    np.testing.assert_allclose(p_tau, p / tau, rtol=1e-12)


def test_command_line_table_and_check(runs, capsys):
    a, b, _ = runs
    assert cli.main(["compare", str(a), str(b), "--quantity", "p"]) == 0
    out = capsys.readouterr().out
    assert "| concentration = 0.8 | p |" in out and "within 2 σ" in out
    # with a vanishing tolerance any difference is outside, and --check says so
    assert cli.main(["compare", str(a), str(b), "--quantity", "p", "--sigma", "1e-12",
                     "--check"]) == 1
    assert "**no**" in capsys.readouterr().out


def test_refusals(runs, capsys, tmp_path):
    a, _, c = runs
    with pytest.raises(ValueError, match="different scenarios"):
        compare_runs(a, c)
    with pytest.raises(ValueError, match="unknown quantity zz; valid: p, tau"):
        compare_runs(a, a, quantities=["zz"])
    with pytest.raises(ValueError, match="positive number"):
        compare_runs(a, a, k=0)
    assert cli.main(["compare", str(a), str(tmp_path)]) == 2
    assert "no results.nc" in capsys.readouterr().err


def test_per_member_results_are_compared_when_a_scenario_has_them(runs):
    _, _, c = runs
    res = compare_runs(c, c)
    assert res.basis == "the per-member results of the scenario"
    assert "a_j" in {r.quantity for r in res.rows}
