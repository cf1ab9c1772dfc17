"""The Godlovitch et al. scenarios (Figs 4–7): short runs checked against the
paper's statements and the exact coagulation solution, and interrupted runs
that resume to the very numbers of an uninterrupted one."""
from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("xarray")
pytest.importorskip("yaml")

import xarray as xr

from physics.params import GODLOVITCH
from physics.scenarios import find_config, get_experiment, resume_run, run_scenario
from physics.scenarios.recorder import Recorder

NAMES = ("godlovitch-kernels", "godlovitch-rafting", "godlovitch-thermo", "scm-analytic")


def _quiet(*args, **kwargs):
    pass


def _run(name, tmp_path, overrides=None, **kw):
    """A run without progress bar, figures or printing; returns (result, dataset)."""
    res = run_scenario(name, overrides=overrides, out=tmp_path / name, workers=1,
                       progress=False, plots=kw.pop("plots", False), log=_quiet, **kw)
    with xr.open_dataset(res.dataset, engine="h5netcdf") as ds:
        return res, ds.load()


def _check_required(name, ds):
    exp = get_experiment(name)
    missing = [v for v in exp.required if v not in ds]
    assert not missing, f"{name}: finished run lacks {missing}"
    for v, (units, _) in exp.variables.items():
        if v in ds:
            assert ds[v].attrs.get("units") == units, v


def test_scenario_files_use_the_tuned_constants():
    """The scenario defaults are the rates and settings of the GODLOVITCH preset."""
    k = find_config("godlovitch-kernels").defaults()
    for kind, params in GODLOVITCH.kernels.items():
        assert k[f"r_{kind}"] == params["r"]
    assert k["beta"] == GODLOVITCH.kernels["exponential"]["beta"]
    assert k["days"] == GODLOVITCH.days
    r = find_config("godlovitch-rafting").defaults()
    assert r["r0"] == GODLOVITCH.r0 and r["raft_factor"] == GODLOVITCH.raft_factor
    assert r["raft_cutoffs"] == list(GODLOVITCH.raft_cutoffs)
    assert r["lambda_target"] == GODLOVITCH.raft_lambda_target
    assert r["days"] == GODLOVITCH.days
    t = find_config("godlovitch-thermo").defaults()
    assert t["r0"] == GODLOVITCH.r0
    assert t["relative_strengths"] == list(GODLOVITCH.relative_strengths)
    assert t["days"] == GODLOVITCH.days
    s = find_config("scm-analytic").defaults()
    assert s["times"] == list(GODLOVITCH.scm_times)
    assert (s["kmax"], s["classes"]) == (GODLOVITCH.scm_kmax, GODLOVITCH.scm_classes)
    for name in NAMES:                        # the --quick forms are valid
        find_config(name).resolve(quick=True)


def test_scm_matches_exact_solution(tmp_path):
    """K = 1 from u_1(0) = 1: relative error of u_k below 1e-6 for k <= 10
    (measured about 1e-11), mass conserved to 1e-9 while the last class is
    empty."""
    _, ds = _run("scm-analytic", tmp_path, {"times": [0.5, 1.0, 2.0, 5.0], "classes": 120,
                                            "kmax": 20})
    _check_required("scm-analytic", ds)
    run = ds.isel(case=0, member=0)
    assert float(run["error_k10_max"]) < 1e-6
    t = run["time"].values
    k = run["k"].values
    exact = (1 + t[:, None] / 2) ** -2 * (t[:, None] / (2 + t[:, None])) ** (k[None, :] - 1)
    np.testing.assert_allclose(run["u_exact"].values, exact, rtol=1e-13)
    np.testing.assert_allclose(run["u"].values[:, :10], exact[:, :10], rtol=1e-6)
    np.testing.assert_allclose(run["number"].values, 1 / (1 + t / 2), rtol=1e-6)
    assert float(run["mass_error_max"]) < 1e-9


def test_every_kernel_gives_an_exponential_tail(tmp_path):
    """Fig. 4 after two model years (the --quick form): R² of the log-linear
    tail fit above 2 m at least 0.95 for each Table 1 kernel (measured 0.98 to
    0.998), area conserved, truncation negligible; kernel names survive the
    NetCDF file."""
    res, ds = _run("godlovitch-kernels", tmp_path, quick=True)
    _check_required("godlovitch-kernels", ds)
    assert list(ds["kernel"].values.astype(str)) == list(GODLOVITCH.kernels)
    assert ds["time"].attrs["units"] == "d"
    r2 = ds["r2_final"].isel(member=0).values
    lam = ds["lambda_final"].isel(member=0).values
    assert np.all(r2 >= 0.95), r2
    assert np.all((lam > 0.5) & (lam < 1.0)), lam          # tail still growing at 720 d
    area = ds["g"].sum("thickness") + ds["open_water"]
    np.testing.assert_allclose(area.values, 1.0, atol=1e-9)
    assert float(ds["top_class_final"].max()) < 1e-8
    labels = [row[0] for row in res.summary]
    assert any("R²" in lab and "constant" in lab for lab in labels)


def test_rafting_speeds_up_tail_formation(tmp_path):
    """Fig. 5: rafting below h_R = 2 m brings λ to 0.9 m at least 1.5 times
    sooner than without rafting (measured 434 against 937 days), and the tail
    stays exponential (R² >= 0.95)."""
    _, ds = _run("godlovitch-rafting", tmp_path, {"days": 1000, "raft_cutoffs": [2.0]})
    _check_required("godlovitch-rafting", ds)
    assert list(ds["h_raft"].values) == [0.0, 2.0]
    t_none, t_raft = ds["t_lambda_target"].isel(member=0).values
    assert np.isfinite(t_none) and np.isfinite(t_raft)
    assert t_none > 1.5 * t_raft
    assert np.all(ds["r2_final"].values >= 0.95)


def test_relative_strength_sets_the_slope(tmp_path):
    """Fig. 6: the tail e-folding thickness falls as R_T grows, and the
    seasonal amplitude of the mean thickness grows with R_T."""
    _, ds = _run("godlovitch-thermo", tmp_path,
                 {"days": 720, "relative_strengths": [0.5, 2.0, 10.0]})
    _check_required("godlovitch-thermo", ds)
    lam = ds["lambda_final"].isel(member=0).values
    amp = ds["mean_thickness_relative_amplitude"].isel(member=0).values
    assert np.all(np.diff(lam) < 0), lam
    assert np.all(np.diff(amp) > 0), amp


class _Stop(Exception):
    """Stands for an interruption (Ctrl-C) half-way through a run."""


@pytest.mark.parametrize("name, overrides", [
    ("godlovitch-kernels", {"kernel": "constant", "days": 300, "output_every": 30}),
    ("scm-analytic", {"times": [0.5, 1.0, 2.0, 5.0], "classes": 100, "kmax": 20}),
])
def test_resume_equals_uninterrupted(tmp_path, monkeypatch, name, overrides):
    """A run stopped half-way (checkpoints at every output) and resumed
    writes exactly the numbers of an uninterrupted run."""
    original = Recorder.progress

    def stop_half_way(self, fraction):
        original(self, fraction)
        if fraction >= 0.5:
            raise _Stop

    monkeypatch.setattr(Recorder, "progress", stop_half_way)
    out = tmp_path / "interrupted"
    with pytest.raises(_Stop):
        run_scenario(name, overrides=overrides, out=out, workers=1, progress=False,
                     plots=False, checkpoint_every=0.0, log=_quiet)
    assert list((out / "jobs").glob("*.ckpt")), "no checkpoint was written"
    monkeypatch.setattr(Recorder, "progress", original)
    resumed = resume_run(out, workers=1, progress=False, plots=False, log=_quiet)
    fresh_res, fresh = _run(name, tmp_path, overrides)
    with xr.open_dataset(resumed.dataset, engine="h5netcdf") as ds:
        ds = ds.load()
    assert set(ds.data_vars) == set(fresh.data_vars)
    for v in fresh.data_vars:
        if v != "member_seed":
            np.testing.assert_array_equal(ds[v].values, fresh[v].values, err_msg=v)
    assert resumed.summary == fresh_res.summary


def test_figures_are_written(tmp_path):
    """Each scenario draws its PNG figures from a short run."""
    small = {"godlovitch-kernels": {"kernel": "additive", "days": 200},
             "godlovitch-rafting": {"days": 200, "raft_cutoffs": [1.0]},
             "godlovitch-thermo": {"days": 200, "relative_strengths": [1.0, 5.0]},
             "scm-analytic": {"times": [1.0, 2.0], "classes": 60, "kmax": 20}}
    for name, overrides in small.items():
        res, _ = _run(name, tmp_path, overrides, plots=True)
        assert res.figures, name
        for path in res.figures:
            assert path.suffix == ".png" and path.stat().st_size > 10_000, path


def test_tune_rate_reaches_its_target():
    """The bisection behind the preset's kernel rates: the e-folding thickness
    of the last trial is close to the target and grows with the rate."""
    from physics.itd import ThorndikeModel
    from physics.scenarios.godlovitch import tune_rate

    r, lam = tune_rate("constant", target=0.6, days=360, iterations=10)
    assert 0.001 < r < 0.008
    assert lam == pytest.approx(0.6, abs=0.02)
    lams = []
    for rate in (0.5 * r, r, 2 * r):
        m = ThorndikeModel("constant", r=rate)
        m.run(360)
        lams.append(m.tail_fit(GODLOVITCH.tail_min).efolding)
    assert lams[0] < lams[1] < lams[2]


@pytest.mark.slow
@pytest.mark.parametrize("kind", GODLOVITCH.KERNEL_NAMES)
def test_tune_rate_gives_the_preset_rates(kind):
    """Tuned for λ = 1 m after 2000 days, the rates are those of GODLOVITCH
    (to their three significant digits)."""
    from physics.scenarios.godlovitch import tune_rate

    params = GODLOVITCH.kernel_params(kind)
    r, lam = tune_rate(kind, **{k: v for k, v in params.items() if k != "r"})
    assert float(f"{r:.3g}") == params["r"]
    assert lam == pytest.approx(GODLOVITCH.tail_target, abs=0.01)
