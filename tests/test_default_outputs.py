"""Every command writes under runs/ unless told otherwise: a first run never
overwrites the records the documentation shows. Those are written only when
a command is asked to (``--docs``, an ``--out`` inside docs/, or ``make
records``). The documentation generators themselves
(``python -m benchmarks.headline``, which rewrites the README's figures, and
``python -m iceenvs.observation_page``) write the pages they exist for and
are not listed here."""
import importlib
import re

import pytest

from benchmarks import SUITES, suite_module

COMMANDS = {
    "agents.train": ["--help"],
    "agents.evaluate": ["--help"],
    "agents.leaderboard": ["--help"],
    "agents.tasks": ["--help"],
    "agents.constant": ["--help"],
    "agents.curves": ["--help"],
    "physics.demo": ["--help"],
    "physics.crosscheck.report": ["all", "--help"],
    "physics.scenarios.cli": ["run", "--help"],
    **{suite_module(suite): ["--help"] for suite in SUITES if suite != "lammps_scaling"},
}
# "default" followed by the path it names, as the help texts spell it
DEFAULT = re.compile(r"\(default:?\s+([^\s),;]+)")


def help_text(module: str, argv: list[str], capsys) -> str:
    main = importlib.import_module(module).main
    with pytest.raises(SystemExit) as exit_info:
        main(argv)
    assert exit_info.value.code == 0
    return " ".join(capsys.readouterr().out.split())


@pytest.mark.parametrize("module", sorted(COMMANDS))
def test_no_default_output_lands_in_the_docs(module, capsys):
    text = help_text(module, COMMANDS[module], capsys)
    defaults = DEFAULT.findall(text)
    assert not [d for d in defaults if d.startswith("docs/")], (module, defaults)


@pytest.mark.parametrize("module, out", [
    ("physics.crosscheck.report", "runs/crosscheck"),
    ("benchmarks.bench_itd", "runs/benchmarks/itd.json"),
    ("agents.leaderboard", "runs/leaderboard"),
    ("physics.demo", "runs/demo"),
])
def test_the_defaults_are_under_runs(module, out, capsys):
    """The pattern above finds the defaults it is meant to (it would pass
    vacuously on help texts it cannot read)."""
    assert out in DEFAULT.findall(help_text(module, COMMANDS[module], capsys))
