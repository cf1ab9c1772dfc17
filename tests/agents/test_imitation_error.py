"""The error that normal noise of σ makes on a teacher's decisions, as a
share of their variance (agents.imitation_error): σ²/variance where no
decision is clipped, nothing where every one is, and a small run."""
import json

import numpy as np
import pytest

from agents.imitation_error import error_share, main
from small_envs import SMALL

NAV = "iceenvs/ShipNavigation-v1"


def test_unclipped_noise_errs_by_sigma_squared_over_the_variance():
    # decisions uniform on [-0.5, 0.5] (variance 1/12); noise of 0.05 stays
    # within [-1, 1] (10 σ), so the share is σ² · 12 = 0.03 up to the
    # sampling of 400 000 squared normals (relative spread sqrt(2 / 4e5) = 0.2 %)
    rng = np.random.default_rng(0)
    w = rng.uniform(-0.5, 0.5, (200_000, 2))
    share = error_share(w, 0.05, np.random.default_rng(1))
    expected = 0.05 ** 2 / np.var(w)
    assert share == pytest.approx(expected, rel=0.01)
    assert error_share(w, 0.0, np.random.default_rng(1)) == 0.0


def test_decisions_clipped_far_beyond_the_noise_make_no_error():
    w = np.tile([[-5.0, 5.0], [5.0, -5.0]], (50, 1))
    assert error_share(w, 0.1, np.random.default_rng(0)) == 0.0


def test_bad_input_is_refused(tmp_path, capsys):
    rng = np.random.default_rng(0)
    with pytest.raises(ValueError, match="two or more decisions"):
        error_share(np.zeros(3), 0.1, rng)
    with pytest.raises(ValueError, match="sigma must be"):
        error_share(np.ones((4, 2)) * np.arange(4)[:, None], -0.1, rng)
    with pytest.raises(ValueError, match="do not vary"):
        error_share(np.ones((4, 2)), 0.1, rng)
    with pytest.raises(SystemExit):
        main(["--out", str(tmp_path), "--noise", "0.1,-1"])
    assert "standard deviations >= 0" in capsys.readouterr().err
    with pytest.raises(SystemExit):
        main(["--out", str(tmp_path), "--episodes", "0"])


def test_a_small_spread_is_recorded(tmp_path):
    kwargs = [f"{k}={v}" for k, v in {**SMALL[NAV], "length": 300.0,
                                      "goal_distance": 150.0}.items()]
    main(["--env-kwargs", *kwargs, "--concentrations", "0.3", "--episodes", "1",
          "--seed", "5", "--noise", "0,0.1", "--out", str(tmp_path), "--no-progress"])
    record = json.loads((tmp_path / "imitation-error.json").read_text())
    at = record["spread"]["0.3"]
    assert at["decisions"] > 5 and at["variance"] > 0.0
    assert at["share"]["0"] == 0.0 and at["share"]["0.1"] > 0.0
    assert "σ = 0.1" in (tmp_path / "imitation-error.md").read_text()


def test_the_noisy_teachers_losses_are_paired_with_the_teacher_and_drawn(tmp_path, capsys):
    from agents.imitation_error import losses

    def episodes(returns):
        return [{"ret": r, "seed": k} for k, r in enumerate(returns)]

    board = {"0.2": {"teacher": episodes([10.0, 20.0, 30.0]),
                     "n1": episodes([9.0, 18.0, 27.0])}}
    lost = losses(board, "teacher", {"n1": 0.1})
    assert lost["0.2"]["n1"]["diff"] == pytest.approx(-2.0, rel=1e-12)     # −1, −2, −3
    assert lost["0.2"]["n1"]["sem"] == pytest.approx(1.0 / np.sqrt(3.0), rel=1e-12)
    with pytest.raises(ValueError, match="not on the board"):
        losses(board, "teacher", {"n2": 0.2})
    (tmp_path / "leaderboard.json").write_text(json.dumps({"episodes": 3}))
    (tmp_path / "episodes.json").write_text(json.dumps(board))
    main(["plot", "--board", str(tmp_path), "--reference", "teacher", "--noisy", "n1=0.1",
          "--out", str(tmp_path / "fig.png")])
    assert (tmp_path / "fig.png").stat().st_size > 1000
    (tmp_path / "episodes.json").unlink()
    with pytest.raises(SystemExit):
        main(["plot", "--board", str(tmp_path), "--reference", "teacher", "--noisy", "n1=0.1",
              "--out", str(tmp_path / "fig.png")])
    assert "no episodes.json" in capsys.readouterr().err
