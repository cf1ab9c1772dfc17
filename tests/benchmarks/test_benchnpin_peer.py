"""The BenchNPIN peer benchmark (``benchmarks.benchnpin_peer``) without its
virtualenv and without the network: the command line, the pins and the
install commands, the stamp that makes the installation idempotent, the
parsing of the measuring script's output, and the measuring script itself
run against a small stand-in for the ``benchnpin`` package."""
from __future__ import annotations

import json
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from benchmarks import benchnpin_peer as peer


def _no_subprocess(*args, **kwargs):
    raise AssertionError(f"nothing should be run here: {args}")


def test_command_line_defaults_and_options(tmp_path):
    args = peer.build_parser().parse_args([])
    assert (args.venv, args.seconds, args.runs, args.seed, args.json) == (None, 20.0, 3, 0, None)
    args = peer.build_parser().parse_args(["--venv", str(tmp_path / "v"), "--seconds", "2.5",
                                           "--runs", "4", "--seed", "7", "--json", "out.json"])
    assert args.venv == tmp_path / "v" and args.seconds == 2.5 and args.runs == 4
    assert args.seed == 7 and args.json == Path("out.json")
    with pytest.raises(SystemExit):
        peer.main(["--runs", "0"])


def test_default_venv_is_under_the_home_directory(monkeypatch, tmp_path):
    monkeypatch.setenv("HOME", str(tmp_path))
    assert peer.default_venv() == tmp_path / ".cache" / "seaice-gym" / "benchnpin-venv"


def test_pins_are_exact_and_leave_torch_out():
    pins = [*peer.RUNTIME_PINS, peer.PACKAGE_PIN]
    names = [p.split("==")[0].lower() for p in pins]
    assert all(p.count("==") == 1 for p in pins)
    assert peer.PACKAGE_PIN == f"benchnpin=={peer.VERSION}" == "benchnpin==0.1.1"
    assert not {"torch", "torchvision", "stable-baselines3", "tensorboard"} & set(names)
    # BenchNPIN's own pins are kept, and NumPy 1.x goes with its Matplotlib
    assert {"matplotlib==3.7.5", "pymunk==6.5.1"} <= set(pins)
    assert any(p.startswith("numpy==1.") for p in pins)
    assert peer.stamp((3, 11, 2)) == dict(pins=pins, python="3.11")


def test_install_commands_make_the_venv_then_install_benchnpin_without_its_deps(tmp_path):
    venv = tmp_path / "venv"
    make, runtime, package = peer.install_commands(venv, python="python3.x")
    assert make == ["python3.x", "-m", "venv", str(venv)]
    py = str(peer.venv_python(venv))
    for command in (runtime, package):
        assert command[:4] == [py, "-m", "pip", "install"]
        assert "--only-binary=:all:" in command
    assert runtime[-len(peer.RUNTIME_PINS):] == list(peer.RUNTIME_PINS)
    assert "--no-deps" not in runtime
    assert package[-2:] == ["--no-deps", peer.PACKAGE_PIN]


def test_child_environment_has_one_thread_and_no_display(monkeypatch):
    monkeypatch.setenv("PYTHONPATH", "/somewhere")
    monkeypatch.setenv("OMP_NUM_THREADS", "8")
    env = peer.child_environment()
    assert "PYTHONPATH" not in env
    for name in ("OMP_NUM_THREADS", "NUMBA_NUM_THREADS", "MKL_NUM_THREADS"):
        assert env[name] == "1"
    assert env["SDL_VIDEODRIVER"] == "dummy" and env["MPLBACKEND"] == "Agg"


def _fake_venv(venv: Path, python: str = "3.11") -> Path:
    exe = peer.venv_python(venv)
    exe.parent.mkdir(parents=True)
    exe.write_text("")
    (venv / "pyvenv.cfg").write_text(f"home = /usr/bin\nversion = {python}.4\n")
    return exe


def test_a_stamped_venv_is_used_as_it_is(monkeypatch, tmp_path):
    venv = tmp_path / "venv"
    exe = _fake_venv(venv)
    (venv / peer.STAMP_NAME).write_text(json.dumps(peer.stamp()))
    monkeypatch.setattr(subprocess, "run", _no_subprocess)
    assert peer.ensure_venv(venv) == exe


def test_a_place_that_is_not_a_venv_or_of_another_python_is_refused(monkeypatch, tmp_path):
    monkeypatch.setattr(subprocess, "run", _no_subprocess)
    taken = tmp_path / "taken"
    taken.mkdir()
    (taken / "notes.txt").write_text("mine")
    with pytest.raises(RuntimeError, match="not a virtualenv"):
        peer.ensure_venv(taken)
    other = tmp_path / "other"
    _fake_venv(other, python="2.7")
    with pytest.raises(RuntimeError, match="made with Python 2.7"):
        peer.ensure_venv(other)


def test_a_failing_install_step_says_which_command_failed(monkeypatch, tmp_path):
    ran = []

    def fail_on_pip(command, **kwargs):
        ran.append(command)
        return subprocess.CompletedProcess(command, 1 if "pip" in command else 0)

    monkeypatch.setattr(subprocess, "run", fail_on_pip)
    venv = tmp_path / "venv"
    with pytest.raises(RuntimeError, match=r"could not install the packages .*pip install"):
        peer.ensure_venv(venv)
    assert [c[2] for c in ran] == ["venv", "pip"]
    assert not (venv / peer.STAMP_NAME).exists()


RAW = dict(steps=[100, 120], seconds=[10.0, 10.0], resets=3, reset_seconds=0.3,
           episodes=dict(lengths=[30, 40], success=1, out_of_bounds=1, truncated=0),
           config=dict(model_time_per_step=0.8, floes=130),
           versions=dict(benchnpin="0.1.1", torch=None))


def test_the_result_line_is_found_among_other_output():
    out = "pygame 2.6.1\nsome message\n" + peer.RESULT_MARKER + json.dumps(RAW) + "\n"
    assert peer.parse_output(out) == RAW
    with pytest.raises(RuntimeError, match="no result line"):
        peer.parse_output("Traceback ...\nKeyError: 'x'\n")


def test_summary_of_a_fake_output():
    res = peer.summarise(RAW)
    assert res["rates"] == [10.0, 12.0]
    assert (res["mean"], res["min"], res["max"]) == (11.0, 10.0, 12.0)
    assert res["std"] == pytest.approx(2 ** 0.5)
    assert res["mean_reset_seconds"] == pytest.approx(0.1)
    assert res["episodes"]["completed"] == 2 and res["episodes"]["mean_length"] == 35
    assert (res["interval"], res["unit"]) == (0.8, "s")
    assert res["config"]["floes"] == 130
    with pytest.raises(RuntimeError):
        peer.summarise(dict(RAW, seconds=[10.0]))


# A stand-in for the parts of benchnpin that the measuring script reads.
FAKE_ENV = '''
import math

import gymnasium as gym
import numpy as np
from gymnasium import spaces


class Cfg(dict):
    __getattr__ = dict.__getitem__


class FakeShipIce(gym.Env):
    def __init__(self):
        self.cfg = Cfg(concentration=0.1, goal_y=9, dt=0.8, target_speed=0.3,
                       egocentric_obs=True, low_dim_state=False,
                       occ=Cfg(map_width=12, map_height=40),
                       ship=Cfg(vertices=[[1, 0], [-1, 0.25], [-1, -0.25]]),
                       sim=Cfg(steps=400, iterations=10))
        self.max_yaw_rate_step = math.pi / 14
        self.env_max_trial = 100
        self.action_space = spaces.Box(low=-1, high=1, shape=(1,), dtype=np.float32)
        self.observation_space = spaces.Box(0, 255, (4, 8, 8), np.uint8)

    def reset(self, seed=None, options=None):
        self.t = 0
        self.start = (5.0, 1.0, math.pi / 2)
        self.obs_dicts = [dict(vertices=np.array([[0, 0], [1, 0], [1, 1], [0, 1]]) + k,
                               radius=0.5) for k in range(3)]
        self.polygons = list(self.obs_dicts)
        return np.zeros((4, 8, 8), np.uint8), {}

    def step(self, action):
        self.t += 1
        done = self.t == 4
        return (np.zeros((4, 8, 8), np.uint8), 0.0, done, False,
                {"trial_success": done})
'''


def test_the_measuring_script_against_a_stand_in_package(monkeypatch, tmp_path, capsys):
    package = tmp_path / "fake" / "benchnpin"
    (package / "environments").mkdir(parents=True)
    (package / "__init__.py").write_text("")
    (package / "environments" / "fake.py").write_text(FAKE_ENV)
    (package / "environments" / "__init__.py").write_text(textwrap.dedent('''
        from gymnasium.envs.registration import register
        register(id="ship-ice-v0", entry_point="benchnpin.environments.fake:FakeShipIce",
                 max_episode_steps=300)
    '''))
    environment = dict(peer.child_environment(), PYTHONPATH=str(package.parent))
    monkeypatch.setattr(peer, "ensure_venv", lambda venv=None: Path(sys.executable))
    monkeypatch.setattr(peer, "child_environment", lambda: environment)
    path = tmp_path / "out" / "peer.json"
    assert peer.main(["--seconds", "0.05", "--runs", "2", "--seed", "3",
                      "--json", str(path)]) == 0
    res = json.loads(path.read_text())
    assert json.loads(capsys.readouterr().out) == res
    assert res["peer"] == "BenchNPIN ship-ice-v0" and res["id"] == "ship-ice-v0"
    assert res["settings"] == dict(seconds=0.05, runs=2, seed=3,
                                   warmup_steps=peer.WARMUP_STEPS, threads=1)
    assert len(res["rates"]) == len(res["steps"]) == len(res["seconds"]) == 2
    for rate, steps, wall in zip(res["rates"], res["steps"], res["seconds"]):
        assert wall >= 0.05 and rate == pytest.approx(steps / wall)
    assert res["resets"] == res["episodes"]["completed"] == res["episodes"]["success"] >= 1
    assert set(res["episodes"]["lengths"]) == {4}
    cfg = res["config"]
    assert cfg["floes"] == 3 and cfg["floe_radius"] == [0.5, 0.5]
    assert cfg["ice_area_fraction"] == pytest.approx(3 / 480)
    assert (cfg["ship_length"], cfg["ship_beam"], cfg["ship_speed"]) == (2.0, 0.5, 0.3)
    assert (cfg["substeps"], cfg["physics_dt"], cfg["model_time_per_step"]) == (400, 0.002, 0.8)
    assert res["interval"] == 0.8 and cfg["max_episode_steps"] == 300
    assert cfg["observation_shape"] == [4, 8, 8] and cfg["action_shape"] == [1]
    assert (cfg["action_low"], cfg["action_high"]) == ([-1.0], [1.0])
