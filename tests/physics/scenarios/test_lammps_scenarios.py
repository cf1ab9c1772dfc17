"""The Herman (2013) scenarios on the LAMMPS engine through the runner:
``--engine lammps`` against our engine, ``--mpi 2`` against one rank, and
the errors of the engine options."""
from __future__ import annotations

import numpy as np
import pytest
import xarray as xr

from physics.lammps_library import lammps_available
from physics.scenarios import run_scenario
from physics.scenarios.cli import main
from physics.scenarios.lammps_job import mpiexec

OK, WHY = lammps_available()
pytestmark = pytest.mark.skipif(not OK, reason=WHY)

#: 200 floes at A = 0.85 under wind for 4 model seconds (2000 steps)
TINY = {"floes": 200, "concentrations": [0.85], "duration": 4.0, "output_interval": 2.0,
        "snapshot_times": [2.0]}


def _run(tmp_path, name, **kw):
    res = run_scenario("herman2013-wind", quick=True, overrides=TINY, out=tmp_path / name,
                       progress=False, plots=False, log=lambda *a: None, **kw)
    with xr.open_dataset(res.dataset, engine="h5netcdf") as ds:
        return ds.load()


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("lammps_runs")
    out = {"numba": _run(tmp, "numba", workers=1), "lammps": _run(tmp, "lammps", engine="lammps")}
    if mpiexec() is not None:
        out["mpi2"] = _run(tmp, "mpi2", engine="lammps", mpi_ranks=2)
    return out


def test_lammps_run_matches_our_engine(runs):
    ours, lmp = runs["numba"], runs["lammps"]
    assert lmp.attrs["engine"] == "lammps" and ours.attrs["engine"] == "numba"
    radius = float(ours["floe_radius"].values[0, 0, 0].mean())
    dx = np.abs(lmp["floe_x"].values - ours["floe_x"].values)
    lx = float(ours["snapshot_lx"].values.ravel()[0])
    dx = np.minimum(dx, lx - dx)
    assert np.nanmax(dx) < 1e-6 * radius, f"positions differ by {np.nanmax(dx):.3g} m"
    for name in ("p", "tau", "z_c", "z_a", "f_nr"):
        a, b = ours[name].values, lmp[name].values
        assert np.allclose(a, b, rtol=1e-5, atol=1e-9), f"{name}: {a} vs {b}"


def test_two_ranks_match_one(runs):
    if "mpi2" not in runs:
        pytest.skip("mpiexec is not available")
    one, two = runs["lammps"], runs["mpi2"]
    assert two.attrs["mpi_ranks"] == 2
    for name in ("floe_x", "floe_y", "p", "tau", "z_c", "contact_force"):
        a, b = one[name].values, two[name].values
        assert np.allclose(a, b, rtol=1e-9, atol=1e-9, equal_nan=True), name


@pytest.mark.parametrize("kw, message", [
    (dict(scenario="herman2011-clustering", engine="lammps"), "numba engine only"),
    (dict(engine="lammps", dask={"local": 2}), "not on Dask"),
    (dict(mpi_ranks=2), "--engine lammps"),
    (dict(engine="lammps", mpi_ranks=0), "positive number of ranks"),
    (dict(engine="cuda"), "unknown engine"),
])
def test_engine_options_are_checked(tmp_path, kw, message):
    scenario = kw.pop("scenario", "herman2013-wind")
    with pytest.raises(ValueError, match=message):
        run_scenario(scenario, quick=True, out=tmp_path / "x", progress=False, plots=False,
                     log=lambda *a: None, **kw)
    assert not (tmp_path / "x").exists()


def test_failing_job_stops_the_run_with_its_reason(tmp_path, capsys):
    code = main(["run", "herman2013-wind", "--quick", "--floes", "200", "--set",
                 "concentrations=[0.8]", "--set", "friction_moves_floes=false", "--engine",
                 "lammps", "--out", str(tmp_path / "fail"), "--no-progress", "--no-plots"])
    err = capsys.readouterr().err
    assert code == 1, err
    assert "case 0, member 0 failed" in err and "tangential_translation" in err, err


def test_resume_keeps_the_engine(tmp_path, capsys):
    code = main(["run", "--resume", str(tmp_path), "--engine", "lammps"])
    assert code == 2
    assert "engine and ranks it was started with" in capsys.readouterr().err
