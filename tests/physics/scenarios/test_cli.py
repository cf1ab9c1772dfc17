"""The ice-scenarios command line: exit codes and messages."""
from __future__ import annotations

import pytest

pytest.importorskip("yaml")

from physics.scenarios import cli


def test_unknown_scenario_lists_the_valid_ones(capsys):
    assert cli.main(["run", "no-such-scenario"]) == 2
    err = capsys.readouterr().err
    assert "unknown scenario 'no-such-scenario'" in err
    assert "herman2013-miz" in err and "Traceback" not in err


def test_a_run_stopped_by_the_physics_says_why_without_a_traceback(monkeypatch, capsys):
    """A run that the engine stops (here inelastic collapse of the hard-disc
    engine, raised as RuntimeError) ends with exit code 1 and the engine's
    message, not a traceback."""
    def collapse(*args, **kwargs):
        raise RuntimeError("inelastic collapse at t = 4248.97924 s: a floe collided 20 times")

    monkeypatch.setattr(cli, "run_scenario", collapse)
    assert cli.main(["run", "herman2011-clustering", "--set", "collision_duration=0"]) == 1
    err = capsys.readouterr().err
    assert err.startswith("ice-scenarios: the run stopped: inelastic collapse at t = 4248.97924 s")
    assert "kept in the run directory" in err
