"""The scenario runner: parameter checks, run directories, the command line
end to end, checkpoints and resume, reproducible ensembles."""
from __future__ import annotations

import pathlib
import pickle
import shutil
import subprocess
import sys
from types import SimpleNamespace

import numpy as np
import pytest

xr = pytest.importorskip("xarray")
pytest.importorskip("yaml")

from physics.scenarios import get_experiment, load_config, resume_run, run_scenario
from physics.scenarios import recorder as recorder_module
from physics.scenarios.config import bundled_configs, parse_set
from physics.scenarios.experiment import experiment_modules, experiments
from physics.scenarios.recorder import checkpoint_files
from physics.scenarios.runner import QUICK_NOTE, find_config, format_summary, member_seeds

# a convergence run of a few seconds
TINY = dict(floes=200, start_concentration=0.84, end_concentration=0.88, rate=2.0,
            output_step=0.004)


# one small run of each kind of engine: Hertz contacts, hard discs, an ITD
KINDS = {
    "hertz": ("herman2013-convergence", TINY),
    "hard-disc": ("herman2011-clustering", dict(floes=300, concentrations=[0.7], duration=200.0,
                                                output_interval=50.0, snapshots=2)),
    "itd": ("godlovitch-kernels", dict(kernel="constant", days=120, output_every=30)),
}


def _run(out, name="herman2013-convergence", **kw):
    kw.setdefault("overrides", TINY)
    return run_scenario(name, out=out, workers=1, progress=False,
                        plots=False, log=lambda *a: None, **kw)


def _resume(out):
    return resume_run(out, workers=1, progress=False, plots=False, log=lambda *a: None)


def _interrupted(out, monkeypatch, after: int, **kw):
    """A run stopped (as by Ctrl-C) right after its checkpoint number
    ``after``, with checkpoints at every output."""
    real = recorder_module.Recorder.checkpoint
    calls = {"n": 0}

    def checkpoint_then_crash(self, state, *, force=False):
        wrote = real(self, state, force=True)
        calls["n"] += 1
        if calls["n"] == after:
            raise KeyboardInterrupt
        return wrote
    monkeypatch.setattr(recorder_module.Recorder, "checkpoint", checkpoint_then_crash)
    with pytest.raises(KeyboardInterrupt):
        _run(out, checkpoint_every=0, **kw)
    monkeypatch.setattr(recorder_module.Recorder, "checkpoint", real)
    assert list((out / "jobs").glob("*.ckpt")) and not (out / "results.nc").exists()


def _assert_same_numbers(res, whole):
    with xr.open_dataset(res.dataset) as ds:
        ds = ds.load()
    assert set(ds.data_vars) == set(whole.data_vars)
    for name in whole.data_vars:
        np.testing.assert_array_equal(ds[name].values, whole[name].values, err_msg=name)


@pytest.mark.parametrize("name, path", bundled_configs().items())
def test_every_shipped_file_parses_and_names_an_experiment(name, path):
    cfg = load_config(path)
    assert cfg.name == name
    get_experiment(name)
    cfg.resolve(quick=True)


def test_every_experiment_has_a_shipped_file_and_every_file_an_experiment():
    assert len(bundled_configs()) >= 9       # the glob sees the shipped files
    assert sorted(experiments()) == sorted(bundled_configs())


def test_the_modules_that_register_an_experiment_are_found(tmp_path):
    """A module with a line beginning with ``@register(`` is an experiment
    module; one that shows the decorator indented (in a docstring) is not,
    nor is a subpackage. Finding them reads the files, imports nothing."""
    package = tmp_path / "extra_scenarios"
    (package / "sub").mkdir(parents=True)
    (package / "__init__.py").write_text("")
    (package / "flows.py").write_text(
        "from physics.scenarios.experiment import Experiment, register\n\n\n"
        "@register('extra-flows')\nclass Flows(Experiment):\n    pass\n")
    (package / "helpers.py").write_text(
        '"""How to add one::\n\n    @register("not-this")\n"""\nraise ImportError\n')
    (package / "sub" / "__init__.py").write_text("@register('nor-this')\n")
    assert experiment_modules(package, "extra_scenarios") == ["extra_scenarios.flows"]
    assert "extra-flows" not in experiments()
    shipped = experiment_modules()
    assert {"physics.scenarios.herman2011", "physics.scenarios.ship_transit"} <= set(shipped)
    assert "physics.scenarios.experiment" not in shipped


def test_an_experiment_builds_its_simulations_on_the_engine_it_was_made_for(monkeypatch):
    """The engine is an argument of the experiment, not a setting of the
    process: two instances in one process build on their own engines."""
    from physics.scenarios import herman2013

    class Built(Exception):
        pass
    seen = []

    def spy(engine, *args, **kwargs):
        seen.append(engine)
        raise Built
    monkeypatch.setattr(herman2013, "hertz_simulation", spy)
    cls = type(get_experiment("herman2013-convergence"))
    p = find_config("herman2013-convergence").resolve(TINY)
    for engine in ("lammps", "numba", "lammps"):
        with pytest.raises(Built):
            cls(engine).simulate(p, {}, 0, recorder_module.Recorder(variables=cls.variables))
    assert seen == ["lammps", "numba", "lammps"]
    assert get_experiment("herman2013-convergence").engine == "numba"
    with pytest.raises(ValueError, match="runs on the numba engine only, not on 'lammps'"):
        get_experiment("herman2011-clustering", "lammps")


def test_unknown_scenario_and_parameter_list_the_valid_ones():
    with pytest.raises(ValueError, match="valid scenarios: .*herman2013-convergence"):
        find_config("herman2099")
    cfg = find_config("herman2013-convergence")
    with pytest.raises(ValueError, match="valid parameters: floes, start_concentration"):
        cfg.resolve({"flows": 10})


@pytest.mark.parametrize("key, value, message", [
    ("floes", 5, r"'floes' must be an integer in \[100, 200000\], got 5"),
    ("floes", 2.5, "must be an integer"),
    ("rate", -1.0, r"'rate' must be a number in \(0, 10\]"),
    ("rate", "fast", "must be a number"),
    ("friction", float("nan"), "friction"),
])
def test_bad_values_name_the_allowed_range(key, value, message):
    with pytest.raises(ValueError, match=message):
        find_config("herman2013-convergence").resolve({key: value})


def test_bad_list_item_names_the_allowed_range():
    with pytest.raises(ValueError, match=r"'concentrations' must be a list of numbers in "
                                         r"\[0.3, 0.93\], got \[0.9, 1.2\]"):
        find_config("herman2013-wind").resolve({"concentrations": [0.9, 1.2]})


def test_set_values_are_yaml():
    assert parse_set(["a=0.5", "b=[0.6, 0.7]", "c=true", "d=text"]) == \
        dict(a=0.5, b=[0.6, 0.7], c=True, d="text")
    with pytest.raises(ValueError, match="key=value"):
        parse_set(["novalue"])


def test_choice_words_that_yaml_reads_as_booleans_stay_words():
    """``--set wind=off`` names the choice "off" of ship-transit's wind; YAML
    1.1 would read it as False, which no choice is."""
    assert parse_set(["wind=off", "w=On", "c=false"]) == dict(wind="off", w="On", c=False)
    assert find_config("ship-transit").resolve(parse_set(["wind=off"]))["wind"] == "off"


def test_broken_scenario_file_is_reported(tmp_path):
    bad = tmp_path / "bad.yaml"
    bad.write_text("name: x\nparameters: {a: {default: [1, }\n")
    with pytest.raises(ValueError, match="not valid YAML"):
        load_config(bad)
    bad.write_text("name: herman2013-convergence\ntitle: t\nparameters:\n"
                   "  floes: {default: 10, min: 100, help: n}\n")
    with pytest.raises(ValueError, match="'floes' must be"):
        load_config(bad)


def test_existing_output_is_not_overwritten_without_force(tmp_path):
    out = tmp_path / "run"
    out.mkdir()
    (out / "precious.txt").write_text("keep me")
    with pytest.raises(FileExistsError, match="--force"):
        _run(out)
    assert (out / "precious.txt").read_text() == "keep me"
    _run(out, force=True)
    assert not (out / "precious.txt").exists() and (out / "results.nc").exists()


def test_member_seeds_are_reproducible_and_distinct():
    assert member_seeds(3, 4) == member_seeds(3, 4)
    assert len(set(member_seeds(3, 4))) == 4
    assert member_seeds(3, 2) == member_seeds(3, 4)[:2]     # more members keep the first ones


def test_same_seed_same_trajectory_other_seed_another(tmp_path):
    a = xr.open_dataset(_run(tmp_path / "a", seed=5).dataset)
    b = xr.open_dataset(_run(tmp_path / "b", seed=5).dataset)
    c = xr.open_dataset(_run(tmp_path / "c", seed=6).dataset)
    np.testing.assert_array_equal(a["p"].values, b["p"].values)
    np.testing.assert_array_equal(a["floe_x"].values, b["floe_x"].values)
    assert not np.array_equal(a["floe_x"].values, c["floe_x"].values)


def test_interrupted_run_resumes_to_the_uninterrupted_result(tmp_path, monkeypatch):
    whole = xr.open_dataset(_run(tmp_path / "whole", seed=2).dataset).load()
    out = tmp_path / "cut"
    _interrupted(out, monkeypatch, 4, seed=2)      # as Ctrl-C right after the 4th checkpoint
    resumed = xr.open_dataset(_resume(out).dataset).load()
    for name in ("time", "p", "z_c", "f_nr", "floe_x", "contact_force", "a_j"):
        np.testing.assert_array_equal(resumed[name].values, whole[name].values, err_msg=name)
    assert not list((out / "jobs").glob("*.ckpt"))


@pytest.mark.parametrize("kind", KINDS)
def test_resume_from_the_newest_checkpoint_or_after_damage_the_previous(tmp_path, monkeypatch,
                                                                         capsys, kind):
    """Every kind of engine resumes bit-for-bit; when its newest checkpoint
    is damaged the run says so and resumes, still bit-for-bit, from the
    previous one."""
    name, overrides = KINDS[kind]
    with xr.open_dataset(_run(tmp_path / "whole", name, overrides=overrides, seed=4).dataset) as ds:
        whole = ds.load()
    out = tmp_path / "cut"
    _interrupted(out, monkeypatch, 3, name=name, overrides=overrides, seed=4)
    newest, previous = checkpoint_files(out / "jobs" / "case00_member00.ckpt")
    assert newest.exists() and previous.exists()
    damaged = tmp_path / "damaged"
    shutil.copytree(out, damaged)
    bad = damaged / "jobs" / newest.name
    bad.write_bytes(bad.read_bytes()[:-100])
    capsys.readouterr()
    _assert_same_numbers(_resume(out), whole)
    assert "cannot be read" not in capsys.readouterr().err
    res = _resume(damaged)
    err = capsys.readouterr().err
    assert f"checkpoint {bad} cannot be read: it is damaged or truncated" in err, err
    assert f"the run continues from {damaged / 'jobs' / previous.name}" in err, err
    _assert_same_numbers(res, whole)
    assert not list((out / "jobs").glob("*.ckpt")) and not list((damaged / "jobs").glob("*.ckpt"))
    with xr.open_dataset(res.dataset) as ds:
        assert "cannot be read" in ds.attrs["notes"]


class _TouchWhenUnpickled:
    """A pickle that creates a file when it is loaded: stands for the code
    an old-style checkpoint received from someone else could run."""

    def __init__(self, path):
        self.path = path

    def __reduce__(self):
        return pathlib.Path.touch, (self.path,)


def test_old_pickle_checkpoint_is_reported_and_never_loaded(tmp_path, monkeypatch, capsys):
    with xr.open_dataset(_run(tmp_path / "whole", seed=1).dataset) as ds:
        whole = ds.load()
    out = tmp_path / "old"
    _interrupted(out, monkeypatch, 2, seed=1)
    newest, previous = checkpoint_files(out / "jobs" / "case00_member00.ckpt")
    previous.unlink()
    marker = tmp_path / "unpickled"
    newest.write_bytes(pickle.dumps({"version": 1, "state": _TouchWhenUnpickled(marker)}))
    capsys.readouterr()
    res = _resume(out)
    err = capsys.readouterr().err
    assert f"checkpoint {newest} cannot be read: it is a pickle file" in err, err
    assert "the run starts again from the beginning" in err, err
    assert not marker.exists()
    _assert_same_numbers(res, whole)
    assert not newest.exists()


def test_sigterm_during_a_kernel_stops_cleanly_and_resumes(tmp_path):
    """kill (SIGTERM) while a run works in its own process, most likely
    inside a compiled kernel: the command stops with the resume hint (not a
    SystemError from inside Numba), keeps its checkpoint, and --resume
    finishes the run."""
    import signal
    import time

    out = tmp_path / "killed"
    cmd = [sys.executable, "-m", "physics.scenarios", "run", "herman2013-miz", "--quick",
           "--floes", "200", "--set", "wind_y=[-5.0]", "--set", "duration=2000", "--out", str(out),
           "--workers", "1", "--checkpoint-every", "0", "--no-progress", "--no-plots"]
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 300
    while not list((out / "jobs").glob("*.ckpt")) and time.monotonic() < deadline:
        assert proc.poll() is None, proc.communicate()
        time.sleep(0.2)
    time.sleep(1.0)                      # well inside the run, between two progress reports
    proc.send_signal(signal.SIGTERM)
    _, err = proc.communicate(timeout=300)
    assert proc.returncode != 0
    assert "SystemError" not in err, err
    assert "interrupted" in err and "--resume" in err, err
    assert list((out / "jobs").glob("*.ckpt")) and not (out / "results.nc").exists()
    done = subprocess.run([sys.executable, "-m", "physics.scenarios", "run", "--resume", str(out),
                           "--no-progress", "--no-plots"],
                          capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr
    ds = xr.open_dataset(out / "results.nc")
    assert float(ds["time"].values[0, 0][-1]) == pytest.approx(2000.0)


def test_ensemble_in_worker_processes(tmp_path):
    res = run_scenario("herman2013-convergence", overrides=TINY, ensemble=2, workers=2,
                       out=tmp_path / "ens", progress=False, plots=False, log=lambda *a: None)
    ds = xr.open_dataset(res.dataset)
    assert ds.sizes["member"] == 2
    assert not np.array_equal(ds["floe_x"].values[0, 0], ds["floe_x"].values[0, 1])
    solo = xr.open_dataset(_run(tmp_path / "solo", seed=0).dataset)
    # member 0 of the ensemble (seed 0) is the run of seed 0's first member
    np.testing.assert_array_equal(ds["p"].values[0, 0], solo["p"].values[0, 0])


def test_command_line_quick_run_end_to_end(tmp_path):
    """What CI checks: a quick scenario from the command line writes the
    NetCDF with the expected variables, the figures and the summary."""
    out = tmp_path / "quick"
    cmd = [sys.executable, "-m", "physics.scenarios", "run", "herman2013-convergence", "--quick",
           "--out", str(out), "--no-progress"]
    done = subprocess.run(cmd, capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr
    assert "| A_J, knee of ln p(A) |" in done.stdout
    ds = xr.open_dataset(out / "results.nc")
    for name in get_experiment("herman2013-convergence").required:
        assert name in ds, name
    assert ds.attrs["scenario"] == "herman2013-convergence" and ds.attrs["quick"] == 1
    assert "numba" in ds.attrs["versions"]
    pngs = sorted(p.name for p in (out / "figures").glob("*.png"))
    assert pngs == ["convergence_force_networks.png", "convergence_pressure_contacts.png"]
    assert all((out / "figures" / p).stat().st_size > 10000 for p in pngs)
    # the same command again refuses to overwrite; a bad value names its range
    again = subprocess.run(cmd, capture_output=True, text=True, timeout=600)
    assert again.returncode == 2 and "--force" in again.stderr
    bad = subprocess.run(cmd[:-3] + ["--set", "rate=-2", "--out", str(tmp_path / "x")],
                         capture_output=True, text=True, timeout=600)
    assert bad.returncode == 2 and "'rate' must be a number in (0, 10]" in bad.stderr
    replot = subprocess.run([sys.executable, "-m", "physics.scenarios", "plot", str(out)],
                            capture_output=True, text=True, timeout=600)
    assert replot.returncode == 0 and "convergence_pressure_contacts.png" in replot.stdout
    summary = subprocess.run([sys.executable, "-m", "physics.scenarios", "summary", str(out)],
                             capture_output=True, text=True, timeout=600)
    assert summary.returncode == 0 and "| A_J, knee of ln p(A) |" in summary.stdout
    assert "Wall time" not in summary.stdout and "Wall time" in (out / "summary.md").read_text()
    # a quick run says that its numbers are not the paper's, in both summaries
    assert QUICK_NOTE in done.stdout and QUICK_NOTE in summary.stdout


def test_only_a_quick_run_says_it_is_not_expected_to_match_the_paper(tmp_path):
    cfg = SimpleNamespace(name="x", title="t", reproduces="r")
    rows = [("A_J", "0.87", "0.918–0.921")]
    assert QUICK_NOTE in format_summary(cfg, rows, 1.0, tmp_path, quick=True)
    assert QUICK_NOTE not in format_summary(cfg, rows, 1.0, tmp_path)
