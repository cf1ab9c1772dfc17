"""The scenario runner's jobs on Dask (--dask-local, --scheduler): the same
results bit for bit as the local process pool, resume, and clear errors."""
from __future__ import annotations

import sys
import time

import numpy as np
import pytest

distributed = pytest.importorskip("distributed")
xr = pytest.importorskip("xarray")
pytest.importorskip("yaml")

from physics.scenarios import cli, run_scenario
from physics.scenarios import jobs as jobs_module

# a two-member convergence ensemble of a few seconds
TINY = dict(floes=200, start_concentration=0.84, end_concentration=0.88, rate=2.0,
            output_step=0.004)
TINY_ARGS = [f"--set={k}={v}" for k, v in TINY.items()]
QUIET = dict(progress=False, plots=False, log=lambda *a: None)


def _load(path):
    with xr.open_dataset(path, engine="h5netcdf") as ds:
        return ds.load()


def _assert_identical(path, reference):
    """Every data variable and coordinate the same bit for bit (NaNs equal)."""
    ds = _load(path)
    assert set(ds.variables) == set(reference.variables)
    for name in reference.variables:
        a, b = ds[name].values, reference[name].values
        assert a.dtype == b.dtype and a.shape == b.shape, name
        same = np.array_equal(a, b, equal_nan=True) if a.dtype.kind in "fc" else \
            np.array_equal(a, b)
        assert same, name


@pytest.fixture(scope="module")
def pool_run(tmp_path_factory):
    """The ensemble on the local process pool, and its wall time."""
    t0 = time.perf_counter()
    res = run_scenario("herman2013-convergence", overrides=TINY, ensemble=2, seed=3, workers=2,
                       out=tmp_path_factory.mktemp("pool") / "run", **QUIET)
    return _load(res.dataset), time.perf_counter() - t0


@pytest.fixture(scope="module")
def scheduler():
    """The address of a Dask scheduler whose one worker runs in this process
    (so that a test can patch what a job does)."""
    with distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=False,
                                  dashboard_address=None) as cluster:
        yield cluster.scheduler_address


def test_dask_local_from_the_command_line_equals_the_process_pool(tmp_path, pool_run):
    reference, pool_wall = pool_run
    out = tmp_path / "dask"
    t0 = time.perf_counter()
    assert cli.main(["run", "herman2013-convergence", *TINY_ARGS, "--ensemble", "2", "--seed",
                     "3", "--dask-local", "2", "--out", str(out), "--no-progress",
                     "--no-plots"]) == 0
    dask_wall = time.perf_counter() - t0
    print(f"wall time: LocalCluster of 2 workers {dask_wall:.1f} s, process pool "
          f"{pool_wall:.1f} s")
    _assert_identical(out / "results.nc", reference)
    assert reference.sizes["member"] == 2
    assert not np.array_equal(reference["floe_x"].values[0, 0], reference["floe_x"].values[0, 1])


def test_scheduler_run_and_resume_equal_the_process_pool(tmp_path, pool_run, scheduler):
    reference, _ = pool_run
    res = run_scenario("herman2013-convergence", overrides=TINY, ensemble=2, seed=3,
                       out=tmp_path / "run", dask={"scheduler": scheduler}, **QUIET)
    _assert_identical(res.dataset, reference)
    # a run with one member left to do, resumed on the scheduler from the command line
    (tmp_path / "run" / "jobs" / "case00_member01.nc").unlink()
    res.dataset.unlink()
    assert cli.main(["run", "--resume", str(tmp_path / "run"), "--scheduler", scheduler,
                     "--no-progress", "--no-plots"]) == 0
    _assert_identical(res.dataset, reference)


def test_a_job_that_fails_on_a_worker_raises_its_error(tmp_path, monkeypatch, scheduler, capsys):
    def collapse(*args, **kwargs):
        raise RuntimeError("inelastic collapse at t = 12.5 s")

    monkeypatch.setattr(jobs_module, "run_job", collapse)
    with pytest.raises(RuntimeError, match="inelastic collapse at t = 12.5 s"):
        run_scenario("herman2013-convergence", overrides=TINY, ensemble=2,
                     out=tmp_path / "a", dask={"scheduler": scheduler}, **QUIET)
    assert cli.main(["run", "herman2013-convergence", *TINY_ARGS, "--out", str(tmp_path / "b"),
                     "--scheduler", scheduler, "--no-progress", "--no-plots"]) == 1
    assert "the run stopped: inelastic collapse at t = 12.5 s" in capsys.readouterr().err


def test_scheduler_and_dask_local_together_are_refused(tmp_path, capsys):
    with pytest.raises(SystemExit) as stop:
        cli.main(["run", "herman2013-convergence", "--out", str(tmp_path / "x"),
                  "--scheduler", "tcp://127.0.0.1:8786", "--dask-local", "2"])
    assert stop.value.code == 2
    assert "not allowed with argument" in capsys.readouterr().err
    with pytest.raises(ValueError, match="not both"):
        run_scenario("herman2013-convergence", out=tmp_path / "y",
                     dask={"scheduler": "tcp://127.0.0.1:8786", "local": 2}, **QUIET)
    assert cli.main(["run", "herman2013-convergence", "--out", str(tmp_path / "z"),
                     "--dask-local", "0"]) == 2
    assert "--dask-local needs a positive number of workers, got 0" in capsys.readouterr().err
    assert not (tmp_path / "y").exists() and not (tmp_path / "z").exists()


def test_an_unreachable_scheduler_is_named(tmp_path):
    t0 = time.perf_counter()
    with pytest.raises(ValueError, match="cannot reach the Dask scheduler at tcp://127.0.0.1:1 "
                                         "within 1 s"):
        run_scenario("herman2013-convergence", overrides=TINY, out=tmp_path / "x",
                     dask={"scheduler": "tcp://127.0.0.1:1", "timeout": 1}, **QUIET)
    assert time.perf_counter() - t0 < 20


def test_without_distributed_the_message_says_what_to_install(tmp_path, monkeypatch, capsys):
    monkeypatch.setitem(sys.modules, "distributed", None)     # import distributed fails
    assert cli.main(["run", "herman2013-convergence", "--out", str(tmp_path / "x"),
                     "--dask-local", "2"]) == 2
    err = capsys.readouterr().err
    assert "pip install 'seaice-gym[dask]'" in err and "Traceback" not in err
    assert not (tmp_path / "x").exists()
