"""The ``herman2011-clustering`` scenario (Herman 2011, Figs 5–10): the two
clustering regimes on a tiny sweep, conservation of floe area in the
recorded clusters, the set-up's drift speeds, checkpoint/restart equal to
an uninterrupted run, and parameter errors."""
from __future__ import annotations

import math

import numpy as np
import pytest

xr = pytest.importorskip("xarray")
pytest.importorskip("yaml")

from physics.scenarios import Recorder, get_experiment, run_scenario
from physics.scenarios.runner import find_config, member_seeds

NAME = "herman2011-clustering"
# two concentrations, 500 floes, 600 model seconds: a few seconds of wall time
TINY = dict(floes=500, concentrations=[0.6, 0.9], duration=600.0, output_interval=100.0,
            snapshots=2, gap_sweep=[0.1, 0.2, 0.5])


@pytest.fixture(scope="module")
def sweep(tmp_path_factory):
    out = tmp_path_factory.mktemp("h11") / "run"
    res = run_scenario(NAME, overrides=TINY, workers=1, progress=False, plots=False, out=out,
                       log=lambda *a: None)
    with xr.open_dataset(res.dataset, engine="h5netcdf") as ds:
        return res, ds.load()


def test_run_holds_the_required_variables(sweep):
    res, ds = sweep
    exp = get_experiment(NAME)
    for name in exp.required:
        assert name in ds, name
    assert ds.sizes["case"] == 2 and ds.sizes["sample"] == 7       # t = 0, 100, ..., 600 s
    assert ds.sizes["snapshot"] == 2
    np.testing.assert_allclose(ds["time"].isel(case=0, member=0), np.arange(7) * 100.0)
    np.testing.assert_allclose(ds["snapshot_time"].isel(case=0, member=0), [0.0, 600.0])
    assert ds["largest_fraction"].attrs["long_name"].startswith("largest-cluster fraction")
    assert (res.directory / "summary.md").exists()


def test_largest_cluster_much_larger_in_close_ice(sweep):
    """Herman (2011), Fig 10: at Ā = 0.9 one cluster holds (nearly) all
    the ice; at Ā = 0.6 the largest cluster stays a fraction of it, of the
    order of the largest floe (0.21 of the ice with 500 floes).

    The bounds at Ā = 0.6 come from the spread over seeds 0-19: a fraction
    of 0.36-0.72 (1.7-3.45 times the largest floe), since with so large a
    largest floe the few floes that join it decide the fraction."""
    _, ds = sweep
    a = ds["concentration"].values
    late = ds["largest_fraction"].isel(member=0, sample=slice(3, None)).mean("sample").values
    low, high = late[np.argmin(a)], late[np.argmax(a)]
    assert high > 0.95
    assert low < 0.8
    assert high - low > 0.2
    largest_floe = float(ds["largest_floe_fraction"].isel(case=0, member=0))
    assert low < 4.0 * largest_floe


def test_largest_cluster_against_the_gap(sweep):
    """``largest_fraction_by_gap``: at d_m = cluster_gap it is the
    recorded largest fraction exactly; a wider gap only joins clusters, so
    the fraction never falls as d_m grows; at t = 0 (random placement) the
    narrowest gap gives at Ā = 0.6 the largest floe or a little more and
    at Ā = 0.9 (a compressed packing) nearly all the ice."""
    _, ds = sweep
    gaps = ds["gap"].values
    np.testing.assert_array_equal(gaps, [0.1, 0.2, 0.5])
    by_gap = ds["largest_fraction_by_gap"].transpose("case", "member", "sample", "gap").values
    k = int(np.flatnonzero(gaps == 0.5)[0])
    np.testing.assert_array_equal(by_gap[..., k], ds["largest_fraction"].values)
    assert np.all(np.diff(by_gap, axis=-1) >= 0.0)
    largest_floe = ds["largest_floe_fraction"].values          # (case, member)
    start = by_gap[:, 0, 0, 0]
    a = ds["concentration"].values
    low, high = np.argmin(a), np.argmax(a)
    assert largest_floe[low, 0] - 1e-12 <= start[low] < 1.5 * largest_floe[low, 0]
    assert start[high] > 0.95


def test_final_clusters_hold_all_the_floe_area(sweep):
    """Σ π r_e² over the recorded rank-ordered cluster radii is F_tot = Ā L²
    (relative 1e-9), and the radii decrease with rank."""
    _, ds = sweep
    for c in range(ds.sizes["case"]):
        run = ds.isel(case=c, member=0)
        re = run["cluster_radius"].isel(sample=-1).values
        re = re[np.isfinite(re)]
        assert re.size == int(run["n_clusters"].isel(sample=-1))
        assert np.all(np.diff(re) <= 0)
        total = float(run["concentration"]) * float(run["box_length"]) ** 2
        assert np.sum(np.pi * re ** 2) == pytest.approx(total, rel=1e-9)
        assert np.isnan(run["cluster_radius"].isel(sample=0).values).all()


def test_set_up_matches_the_paper(sweep):
    """Table I of Herman (2011): the sample follows α_r = 1.5 (ML estimate
    within 0.1), the largest floes drift at about 0.25 m/s and the smallest
    (0.77 m) at about 0.16 m/s in free drift (the Physics page: physics-drag, to 0.01 m/s),
    τ of 300–1000 s; floes start almost at rest and speed up towards u_eq."""
    _, ds = sweep
    run = ds.isel(case=0, member=0)
    assert float(run["fsd_alpha"]) == pytest.approx(1.5, abs=0.1)
    assert float(run["ueq_max"]) == pytest.approx(0.25, abs=0.01)
    assert float(run["ueq_min"]) == pytest.approx(0.16, abs=0.01)
    assert 250.0 < float(run["tau_min"]) < 400.0 and 900.0 < float(run["tau_max"]) < 1100.0
    v = run["drift_velocity"].values
    assert abs(v[0]) < 0.005 and 0.05 < v[-1] < float(run["ueq_max"])
    assert np.all(np.diff(v) > 0)
    # pair distributions: g_ffd of the clustered state exceeds 1 at contact
    g = run["g_ffd"].isel(sample=-1).values
    assert g[0] > 1.5


def test_resume_equals_an_uninterrupted_run(tmp_path):
    """A run stopped between an output and its checkpoint resumes from the
    previous checkpoint and ends bit-for-bit where the uninterrupted run
    ends."""
    exp = get_experiment(NAME)
    p = find_config(NAME).resolve(dict(floes=300, concentrations=[0.7], duration=400.0,
                                       output_interval=50.0, snapshots=2))
    case = exp.cases(p)[0]
    seed = member_seeds(3, 1)[0]

    ref = Recorder(variables=exp.variables)
    exp.simulate(p, case, seed, ref)
    ref = ref.dataset()

    class Stop(Exception):
        pass

    def stop_halfway(fraction):
        if fraction >= 0.5:
            raise Stop

    ckpt = tmp_path / "job.ckpt"
    first = Recorder(ckpt, 0.0, stop_halfway, exp.variables)
    with pytest.raises(Stop):
        exp.simulate(p, case, seed, first)
    second = Recorder(ckpt, 0.0, None, exp.variables)
    state = second.restore()
    assert state is not None and 0 < state["step"] < 8
    exp.simulate(p, case, seed, second)
    ds = second.dataset()
    for name in ("time", "largest_fraction", "n_clusters", "alpha", "collisions",
                 "cluster_radius", "g_ffd", "floe_x", "floe_u"):
        np.testing.assert_array_equal(ds[name].values, ref[name].values, err_msg=name)
    assert float(ds["sweep_time"]) == float(ref["sweep_time"])


@pytest.mark.parametrize("key, value, message", [
    ("concentrations", [0.6, 0.95], r"'concentrations' must be a list of numbers in \[0.1, 0.9\]"),
    ("cluster_gap", 0.0, r"'cluster_gap' must be a number in \(0, 5\]"),
    ("gap_sweep", [0.1, 0.0], r"'gap_sweep' must be a list of numbers in \[0.01, 5\]"),
    ("restitution", 1.5, r"'restitution' must be a number in \(0, 1\]"),
    ("fsd", "lognormal", "'fsd' must be one of rank, random"),
    ("floes", 50, r"'floes' must be an integer in \[100, 200000\]"),
])
def test_bad_values_name_the_allowed_range(tmp_path, key, value, message):
    with pytest.raises(ValueError, match=message):
        run_scenario(NAME, overrides={key: value}, workers=1, progress=False, plots=False,
                     out=tmp_path / "bad", log=lambda *a: None)


def test_too_few_floes_for_close_ice_is_explained():
    exp = get_experiment(NAME)
    p = find_config(NAME).resolve(dict(floes=200, concentrations=[0.6, 0.9]))
    with pytest.raises(ValueError, match="use more floes"):
        exp.cases(p)
    assert math.isfinite(exp.workload(find_config(NAME).resolve(), {"concentration": 0.9}))


def test_drag_update_interval_and_tc_duration_reach_the_engine(monkeypatch):
    """max_velocity_step and collision_duration default to Table I of the
    paper (1 s, 0.1 s) and are handed to the hard-disc engine as set."""
    import physics
    from physics.params import HERMAN2011

    cfg = find_config(NAME)
    defaults = cfg.defaults()
    assert defaults["max_velocity_step"] == HERMAN2011.max_velocity_step == 1.0
    assert defaults["collision_duration"] == HERMAN2011.collision_duration == 0.1
    seen = {}

    class Spy(physics.HardDiskSimulation):
        def __init__(self, *args, **kwargs):
            seen.update(kwargs)
            super().__init__(*args, **kwargs)

    monkeypatch.setattr(physics, "HardDiskSimulation", Spy)
    exp = get_experiment(NAME)
    p = cfg.resolve(dict(floes=200, concentrations=[0.6], duration=20.0, output_interval=10.0,
                         max_velocity_step=0.25, collision_duration=0.0))
    exp.simulate(p, exp.cases(p)[0], 1, Recorder(variables=exp.variables))
    assert (seen["max_velocity_step"], seen["collision_duration"]) == (0.25, 0.0)
