"""python -m agents.frames: the frames, the contact sheet and the overview of
one episode, the same for the same seed, of the episode the leaderboard
scores; policies of one's own and trained runs; refused arguments."""
from pathlib import Path

import numpy as np
import pytest

from agents import frames
from cli_checks import assert_refused

#: a short v1 field without leads: 200 m to the goal line, about 50 steps
SHORT = ["--env-kwargs", "goal_distance=200", "length=500", "leads=0", "--concentration", "0.3",
         "--no-progress"]
SHORT_KWARGS = {"goal_distance": 200, "length": 500, "leads": 0, "concentration": 0.3}


def _png(path: Path) -> np.ndarray:
    import matplotlib.image as mpimg

    return (mpimg.imread(path)[..., :3] * 255).round().astype(np.uint8)


def test_frames_writes_the_frames_the_contact_sheet_and_the_overview(tmp_path, capsys):
    out = tmp_path / "frames"
    episode = frames.main(["straight", *SHORT, "--every", "20", "--out", str(out)])
    last = episode["length"]
    assert 40 < last < 80                      # the straight line reaches the goal line
    steps = [0, 20, 40, last]
    assert [f["step"] for f in episode["frames"]] == steps
    assert sorted(p.name for p in out.iterdir()) == sorted(
        [f"frame_{s:04d}.png" for s in steps] + ["contact_sheet.png", "overview.png"])
    shots = [_png(out / f"frame_{s:04d}.png") for s in steps]
    for shot in shots:
        assert shot.shape[1] >= 800 and 400 <= shot.shape[0] < shot.shape[1]
    # the ship moves: the plots above the panels differ from frame to frame
    rows = episode["frames"][0]["picture_rows"]
    assert 300 < rows < shots[0].shape[0]
    for a, b in zip(shots, shots[1:]):
        assert np.mean(np.any(a[:rows] != b[:rows], axis=-1)) > 0.01
    overview = _png(out / "overview.png")
    # the whole 500 m × 200 m channel, in a wider plot than the window's 400 m × 200 m
    assert overview.shape[1] > shots[-1].shape[1]
    sheet = _png(out / "contact_sheet.png")
    # four tiles in two columns and the overview under them
    assert sheet.shape[1] == frames.SHEET_WIDTH
    assert sheet.shape[0] > 1.5 * sheet.shape[1] * rows / shots[0].shape[1]
    printed = capsys.readouterr().out
    assert "return" in printed and "kN s/m" in printed and "reached the goal" in printed
    assert str(out) in printed


def test_the_same_seed_draws_the_same_frames(tmp_path):
    one, two = tmp_path / "one", tmp_path / "two"
    first = frames.main(["lattice", *SHORT, "--every", "25", "--out", str(one)])
    second = frames.main(["lattice", *SHORT, "--every", "25", "--out", str(two)])
    assert first["ret"] == second["ret"]
    names = sorted(p.name for p in one.iterdir())
    assert names == sorted(p.name for p in two.iterdir())
    for name in names:
        assert np.array_equal(_png(one / name), _png(two / name)), name
    # another field draws other frames
    other = frames.main(["lattice", *SHORT, "--seed", "10001", "--every", "25",
                         "--out", str(tmp_path / "other")])
    assert not np.array_equal(_png(one / "frame_0025.png"),
                              _png(tmp_path / "other" / "frame_0025.png"))
    assert other["ret"] != first["ret"]
    # frames at model times, in the overview: those of an earlier run are replaced
    again = frames.main(["lattice", *SHORT, "--times", "0,31,1e4", "--view", "overview",
                         "--out", str(one)])
    assert [f["step"] for f in again["frames"]] == [0, 16]         # steps of 2 s
    assert again["times_missed"] == [1e4]
    assert sorted(p.name for p in one.glob("frame_*.png")) == ["frame_0000.png",
                                                              "frame_0016.png"]
    wide = _png(one / "frame_0016.png")
    assert wide.shape[1] > 2 * again["frames"][1]["picture_rows"]


def test_the_frames_are_of_the_episode_the_leaderboard_scores(tmp_path):
    """Drawing reads the state and changes nothing: the episode is the one
    agents.rollouts.run_episode plays on the same field without frames; the
    swath planner's course is drawn, the straight line has none."""
    from iceenvs.rendering import ROUTE

    from agents.baselines import make_baseline
    from agents.envs import make_checked_env
    from agents.rollouts import run_episode

    drawn = frames.main(["swath", *SHORT, "--every", "20", "--out", str(tmp_path / "swath")])
    env = make_checked_env("iceenvs/ShipNavigation-v1", SHORT_KWARGS, seed=10_000)
    try:
        plain = run_episode(env, make_baseline("swath", env, seed=10_000), 10_000, None)
    finally:
        env.close()
    assert drawn["ret"] == plain["ret"] and drawn["length"] == plain["length"]
    assert drawn["final"] == plain["final"]

    def has_route(path):
        return np.any(np.all(_png(path) == ROUTE, axis=-1))

    assert has_route(tmp_path / "swath" / "frame_0020.png")
    frames.main(["straight", *SHORT, "--every", "20", "--out", str(tmp_path / "straight")])
    assert not has_route(tmp_path / "straight" / "frame_0020.png")


POLICY_FILE = """
import numpy as np

class Weave:
    def __init__(self, env, seed=0, turn=0.5):
        self.turn = float(turn)

    def reset(self, seed=None):
        self.steps = 0

    def predict(self, obs, deterministic=True):
        self.steps += 1
        return np.array([self.turn if self.steps % 20 < 10 else -self.turn], np.float32), None
"""


def test_a_policy_of_ones_own_and_the_default_output(tmp_path, monkeypatch):
    """A policy class in a file, with an argument, plays; by default the
    files land under runs/, never under docs/, and a frame is drawn about
    every eighth of a straight transit (200 m at 4 m a step: every 6 steps)."""
    monkeypatch.chdir(tmp_path)
    (tmp_path / "my_policy.py").write_text(POLICY_FILE)
    episode = frames.main(["my_policy.py:Weave?turn=0.8", *SHORT])
    out = episode["out"]
    assert out == Path("runs/frames/ShipNavigation-v1_Weave-turn=0.8_10000_A0.3")
    assert (out / "contact_sheet.png").is_file() and (out / "overview.png").is_file()
    steps = [f["step"] for f in episode["frames"]]
    assert steps[:3] == [0, 6, 12] and steps[-1] == episode["length"]
    assert 9 <= len(steps) <= 12
    assert (out / "frame_0006.png").is_file()
    # it weaves: a longer path than the straight line's 200 m
    assert episode["final"]["path_length"] > 201.0
    assert frames.build_parser().get_default("out") is None
    assert frames.default_out("iceenvs/ShipNavigation-v1", "runs/ppo@4096", 7).parts[:2] == \
        ("runs", "frames")


def test_a_trained_run_plays_as_it_was_trained(tmp_path):
    """A run of agents.train is played on its own environment with its own
    control (control="course") and observation, as the leaderboard plays it."""
    import gymnasium as gym

    from agents import train
    from agents.rollouts import TrainedPolicy, run_agent_kwargs, run_episode

    run = tmp_path / "run"
    train.main(["--env", "iceenvs/ShipNavigation-v1", "--algo", "ppo", "--timesteps", "64",
                "--n-envs", "1", "--seed", "1", "--out", str(run), "--eval-freq", "0",
                "--no-progress", "--hyperparams", "n_steps=32", "batch_size=32", "pretrain=null",
                "--env-kwargs", "control=course", "goal_distance=200.0", "length=500.0"])
    episode = frames.main([str(run), *SHORT, "--every", "100", "--out", str(tmp_path / "f")])
    assert (tmp_path / "f" / "contact_sheet.png").is_file()
    agent = run_agent_kwargs(run)
    assert agent["control"] == "course"
    env = gym.make("iceenvs/ShipNavigation-v1", **agent, **SHORT_KWARGS)
    try:
        alone = run_episode(env, TrainedPolicy(run), 10_000, None)
    finally:
        env.close()
    assert episode["ret"] == alone["ret"]


def test_the_contact_sheet_keeps_the_first_and_last_of_many_frames():
    assert frames._spread(list(range(5)), 12) == [0, 1, 2, 3, 4]
    kept = frames._spread(list(range(100)), frames.SHEET_TILES)
    assert len(kept) == frames.SHEET_TILES and kept[0] == 0 and kept[-1] == 99
    assert all(b - a >= 8 for a, b in zip(kept, kept[1:]))


NO_FRAMES_ENV = """
import gymnasium as gym
from iceenvs.ship_navigation_v1 import ShipNavigationV1Env

class NoFrames(ShipNavigationV1Env):
    metadata = {"render_modes": [], "render_fps": 10}

gym.register("frames_test/NoFrames-v0", entry_point=NoFrames, max_episode_steps=10)
"""


@pytest.mark.parametrize("args, words", [
    (["nonsense"], ["unknown policy 'nonsense'", "straight", "lattice", "module:Class"]),
    (["no_such_module_here:Policy"], ["no module 'no_such_module_here'"]),
    (["missing_policy_file.py:Policy"], ["no file", "missing_policy_file.py"]),
    (["agents.baselines:NoSuchPolicy"], ["has no 'NoSuchPolicy'"]),
    (["straight", "--every", "0"], ["--every must be at least 1"]),
    (["straight", "--view", "sideways"], ["--view", "invalid choice: 'sideways'"]),
    (["straight", "--times", "10,soon"], ["--times"]),
    (["straight", "--concentration", "0.3", "--env-kwargs", "concentration=0.2"],
     ["use --concentration"]),
    (["straight", "--env", "iceenvs/NoSuchEnv-v0"], ["NoSuchEnv-v0"]),
    (["straight", "--env-kwargs", "goal_distance=-5"], ["goal_distance"]),
    (["no/such/run@100"], ["not an existing run directory"]),
])
def test_frames_refuses_bad_arguments(tmp_path, capsys, args, words):
    assert_refused(frames.main, args, words, tmp_path / "none", capsys)


def test_an_environment_without_frames_is_refused(tmp_path, capsys, monkeypatch):
    (tmp_path / "frames_test_no_frames.py").write_text(NO_FRAMES_ENV)
    monkeypatch.syspath_prepend(str(tmp_path))
    assert_refused(frames.main, ["straight", "--env",
                                 "frames_test_no_frames:frames_test/NoFrames-v0"],
                   ["draws no frames", "rgb_array"], tmp_path / "none", capsys)
