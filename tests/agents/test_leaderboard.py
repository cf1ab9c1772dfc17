"""The leaderboard command: its files, the straight line's ratios to itself,
merging a policy in, rendering again, and refused arguments."""
import json
import math

import pytest

from agents import leaderboard
from cli_checks import assert_refused

SHORT = ["--env-kwargs", "goal_distance=200.0", "length=500.0"]


def test_leaderboard_writes_its_table_and_merges_a_policy(tmp_path):
    out = tmp_path / "board"
    base = ["--concentrations", "0.2", "--episodes", "2", "--processes", "1",
            "--out", str(out)] + SHORT
    report = leaderboard.main(base + ["--policies", "straight"])
    assert {p.name for p in out.iterdir()} == {"leaderboard.json", "leaderboard.md",
                                               "leaderboard.png"}
    s = report["summary"]["0.2"]["straight"]
    # no floe hit on some field: its ratio is undefined (NaN), never another number
    ratio = s["ratio_impulse_per_metre"]["mean"]
    assert ratio == 1.0 or math.isnan(ratio)
    assert s["ratio_path_length"]["mean"] == 1.0 and s["success_rate"] == 1.0
    merged = leaderboard.main(base + ["--policies", "straight,lattice", "--merge"])
    assert list(merged["summary"]["0.2"]) == ["straight", "lattice"]
    # the straight line's episodes are kept, not run again
    assert merged["episodes_detail"]["0.2"]["straight"] == \
        json.loads(json.dumps(report["episodes_detail"]["0.2"]["straight"]))
    # --replace runs a kept policy again: the same fields, the same episodes
    again = leaderboard.main(base + ["--policies", "straight", "--merge", "--replace",
                                     "straight"])
    assert list(again["summary"]["0.2"]) == ["straight", "lattice"]
    assert [e["ret"] for e in again["episodes_detail"]["0.2"]["straight"]] == \
        [e["ret"] for e in merged["episodes_detail"]["0.2"]["straight"]]
    text = (out / "leaderboard.md").read_text()
    assert "### Does route choice pay?" in text and "| 0.2 | lattice |" in text
    (out / "leaderboard.md").unlink()
    leaderboard.main(["--render", "--out", str(out)])
    assert (out / "leaderboard.md").read_text() == text


@pytest.mark.parametrize("args, message", [
    (["--policies", "straight,nonsense"], "unknown policy"),
    (["--episodes", "1"], "at least 2"),
    (["--concentrations", "0.2", "--env-kwargs", "concentration=0.3"], "concentrations"),
    (["--trained", "ppo=/no/such/run"], "existing run directory"),
    (["--merge"], "does not exist"),
    (["--render"], "does not exist"),
    (["--replace", "straight"], "needs --merge"),
])
def test_leaderboard_refuses_bad_arguments(tmp_path, capsys, args, message):
    assert_refused(leaderboard.main, args, [message], tmp_path / "none", capsys)
