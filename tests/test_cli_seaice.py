"""The ``seaice`` command: its help, the forwarding of each sub-command to
its tool's entry point, and its usage errors."""
from __future__ import annotations

import importlib
import subprocess
import sys
from pathlib import Path

import pytest

from seaice_gym import __version__
from seaice_gym import cli

SUBCOMMANDS = ["train", "evaluate", "tune", "scenarios", "crosscheck", "bench", "validate", "demo"]


def _exit(argv, capsys) -> tuple[int, str, str]:
    """(exit status, stdout, stderr) of ``seaice argv`` that exits through
    argparse (help or a usage error)."""
    with pytest.raises(SystemExit) as stop:
        cli.main(argv)
    out, err = capsys.readouterr()
    return stop.value.code, out, err


def test_help_lists_every_subcommand_with_its_description(capsys, monkeypatch):
    monkeypatch.setenv("COLUMNS", "100")
    assert list(cli.COMMANDS) == SUBCOMMANDS
    code, out, _ = _exit(["--help"], capsys)
    assert code == 0 and out.startswith("usage: seaice ")
    for name, (_, text) in cli.COMMANDS.items():
        assert name in out and text in out, name
    assert _exit(["--version"], capsys)[1].strip() == f"seaice {__version__}"


@pytest.mark.parametrize("sub", SUBCOMMANDS)
def test_each_subcommand_shows_its_entry_points_help(capsys, sub):
    code, out, _ = _exit([sub, "--help"], capsys)
    assert code == 0
    assert out.startswith(f"usage: seaice {sub} "), out[:200]


@pytest.mark.parametrize("argv, shown", [
    (["scenarios", "run", "--help"], "--resume RUN_DIR"),
    (["train", "--help"], "--algo"),
    (["evaluate", "--help"], "--episodes"),
    (["crosscheck", "--help"], "pymunk"),
    (["validate", "--help"], "Validation report of the Hertz engine"),
    (["demo", "physics", "--help"], "--floes"),
    (["demo", "agents", "--help"], "--timesteps"),
    (["bench", "hertz", "--help"], "--memory-floes"),
    (["bench", "scaling", "--help"], "--workloads"),
    (["bench", "where_time_goes", "--help"], "--episode-seed"),
    (["bench", "free_drift", "--help"], "--late-after"),
    (["bench", "headline", "--help"], "--readme"),
])
def test_the_help_is_the_entry_points_own(capsys, argv, shown):
    code, out, _ = _exit(argv, capsys)
    assert code == 0 and shown in out
    assert out.startswith("usage: seaice " + " ".join(argv[:-1]))


def test_unknown_subcommand_lists_the_valid_ones(capsys):
    code, _, err = _exit(["nope"], capsys)
    assert code == 2 and "invalid choice: 'nope'" in err
    for name in SUBCOMMANDS:
        assert repr(name) in err, name
    code, _, err = _exit([], capsys)
    assert code == 2 and "required: command" in err
    code, _, err = _exit(["bench", "nope"], capsys)
    assert code == 2 and "'hertz'" in err and "'environments'" in err


def test_arguments_are_forwarded_and_the_status_returned(monkeypatch):
    calls = []

    def fake_scenarios(argv, prog="ice-scenarios"):
        calls.append(("scenarios", argv, prog))
        return 3

    def fake_validate(argv, prog="python -m physics.validate"):
        calls.append(("validate", argv, prog))
        return 0

    def fake_train(argv, prog="python -m agents.train"):
        calls.append(("train", argv, prog))
        return "runs/x"                      # not an exit status: success

    monkeypatch.setattr(importlib.import_module("physics.scenarios.cli"), "main", fake_scenarios)
    monkeypatch.setattr(importlib.import_module("physics.validate"), "main", fake_validate)
    monkeypatch.setattr(importlib.import_module("agents.train"), "main", fake_train)
    assert cli.main(["scenarios", "run", "herman2013-convergence", "--quick"]) == 3
    assert cli.main(["validate"]) == 0
    assert cli.main(["train", "--env", "E", "--help-me"]) == 0
    assert calls == [("scenarios", ["run", "herman2013-convergence", "--quick"],
                      "seaice scenarios"),
                     ("validate", [], "seaice validate"),
                     ("train", ["--env", "E", "--help-me"], "seaice train")]


def test_demo_runs_the_engine_demo_then_the_training_demo(monkeypatch):
    calls = []
    physics_demo = importlib.import_module("physics.demo")
    agents_demo = importlib.import_module("agents.demo")
    monkeypatch.setattr(physics_demo, "main",
                        lambda argv, prog="": calls.append(("physics", argv, prog)) or 0)
    monkeypatch.setattr(agents_demo, "main",
                        lambda argv, prog="": calls.append(("agents", argv, prog)) or {})
    assert cli.main(["demo"]) == 0
    assert calls == [("physics", [], "seaice demo physics"), ("agents", [], "seaice demo agents")]
    calls.clear()
    assert cli.main(["demo", "agents", "--timesteps", "10"]) == 0
    assert calls == [("agents", ["--timesteps", "10"], "seaice demo agents")]
    monkeypatch.setattr(physics_demo, "main", lambda argv, prog="": 1)
    calls.clear()
    assert cli.main(["demo"]) == 1 and calls == []     # a failed engine demo stops there


def test_bench_forwards_to_the_suite(monkeypatch, capsys):
    benchmarks = pytest.importorskip("benchmarks")
    for suite in cli.BENCH_SUITES:
        importlib.import_module(cli.bench_module(suite))   # every listed suite exists
    assert all(cli.bench_module(s) == benchmarks.suite_module(s) for s in benchmarks.SUITES)
    assert set(cli.BENCH_SUITES) >= set(getattr(benchmarks, "SUITES", ()))
    seen = []
    monkeypatch.setattr(importlib.import_module("benchmarks.bench_itd"), "main",
                        lambda argv: seen.append(argv) or 0)
    assert cli.main(["bench", "itd", "--quick"]) == 0 and seen == [["--quick"]]
    code, out, _ = _exit(["bench", "--help"], capsys)
    assert code == 0 and all(s in out for s in cli.BENCH_SUITES)


def test_without_the_benchmarks_bench_says_where_they_are_and_the_rest_works(monkeypatch, capsys,
                                                                           tmp_path):
    monkeypatch.chdir(tmp_path)                                # not a checkout
    monkeypatch.delenv(cli.SOURCE_VARIABLE, raising=False)
    monkeypatch.setitem(sys.modules, "benchmarks", None)       # and not on the module path
    monkeypatch.delitem(sys.modules, "benchmarks.bench_hertz", raising=False)
    code, _, err = _exit(["bench", "hertz"], capsys)
    assert code == 2 and "Traceback" not in err
    assert "not installed" in err and "source checkout" in err
    for hint in ("`seaice bench hertz`", "`python -m benchmarks.bench_hertz`", "from the root",
                 cli.SOURCE_VARIABLE):
        assert hint in err, hint
    assert _exit(["bench", "--help"], capsys)[0] == 0
    assert _exit(["scenarios", "--help"], capsys)[0] == 0


def test_a_source_variable_without_benchmarks_is_refused(monkeypatch, capsys, tmp_path):
    monkeypatch.setenv(cli.SOURCE_VARIABLE, str(tmp_path))
    code, _, err = _exit(["bench", "itd"], capsys)
    assert code == 2 and f"{cli.SOURCE_VARIABLE}={str(tmp_path)!r}" in err
    assert "root of a source checkout" in err


@pytest.mark.parametrize("named", [False, True])
def test_bench_runs_the_suites_of_the_checkout_in_the_current_directory_or_named(
        monkeypatch, tmp_path, named):
    """A checkout (here a stand-in with one suite) in the current directory,
    or named by the variable from elsewhere, comes first on the module path,
    as ``python -m benchmarks.bench_SUITE`` from its root."""
    checkout = tmp_path / "checkout"
    (checkout / "benchmarks").mkdir(parents=True)
    (checkout / "benchmarks" / "__init__.py").write_text("")
    (checkout / "benchmarks" / "bench_itd.py").write_text(
        "seen = []\n\ndef main(argv):\n    seen.append(argv)\n    return 5\n")
    if named:
        monkeypatch.setenv(cli.SOURCE_VARIABLE, str(checkout))
        monkeypatch.chdir(tmp_path)
    else:
        monkeypatch.delenv(cli.SOURCE_VARIABLE, raising=False)
        monkeypatch.chdir(checkout)
    monkeypatch.setattr(sys, "path", list(sys.path))
    for name in ("benchmarks", "benchmarks.bench_itd"):
        monkeypatch.delitem(sys.modules, name, raising=False)
    assert cli.benchmarks_checkout() == checkout.resolve()
    # --no-json: should the real suite run instead, it writes nothing
    assert cli.main(["bench", "itd", "--quick", "--no-json"]) == 5
    suite = sys.modules["benchmarks.bench_itd"]
    assert Path(suite.__file__).resolve() == (checkout / "benchmarks" / "bench_itd.py").resolve()
    assert suite.seen == [["--quick", "--no-json"]]


def test_console_script_and_module_entry_points():
    tomllib = pytest.importorskip("tomllib")
    root = Path(__file__).resolve().parents[1]
    project = tomllib.loads((root / "pyproject.toml").read_text())["project"]
    assert project["scripts"]["seaice"] == "seaice_gym.cli:main"
    assert project["scripts"]["ice-scenarios"] == "physics.scenarios.cli:main"
    script = Path(sys.executable).with_name("seaice")
    assert script.exists(), "the seaice script is missing: install the project again (make setup)"
    for command in ([str(script)], [sys.executable, "-m", "seaice_gym"]):
        done = subprocess.run(command + ["--help"], capture_output=True, text=True, timeout=120)
        assert done.returncode == 0 and all(s in done.stdout for s in SUBCOMMANDS)
        wrong = subprocess.run(command + ["nope"], capture_output=True, text=True, timeout=120)
        assert wrong.returncode == 2 and "invalid choice" in wrong.stderr
