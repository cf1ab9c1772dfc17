"""Comparing shipped sets of training seeds (agents.alternatives): the
paired differences by benchmark episode and by training seed, and the
refusals of sets that cannot be compared."""
import json

import pytest
import yaml

from agents.alternatives import main


def _set(directory, algo, per_seed, chosen, env="iceenvs/WindDrift-v0"):
    """A directory as agents.benchmark ship writes it: ``per_seed`` maps a
    training seed to its benchmark returns."""
    directory.mkdir(parents=True)
    (directory / "args.yaml").write_text(yaml.safe_dump({"algo": algo, "env": env}))
    seeds = [dict(seed=n, selection=dict(mean=float(n), sem=0.0, std=0.0, n=2),
                  evaluation=dict(mean=sum(r) / len(r), sem=0.5, std=1.0, n=len(r)),
                  returns=r, training=dict(steps=1000 * n, wall_seconds=60.0 * n))
             for n, r in per_seed.items()]
    means = [s["evaluation"]["mean"] for s in seeds]
    (directory / "seeds.json").write_text(json.dumps(dict(
        env=env, chosen_seed=chosen, evaluation_episodes="3 seeded 40000 + k",
        across_seeds=dict(mean=sum(means) / len(means), std=0.0, min=min(means),
                          max=max(means)), seeds=seeds, command="ship")))
    return directory


def test_differences_are_paired_by_episode_and_by_seed(tmp_path):
    ref = _set(tmp_path / "ppo", "ppo", {1: [1, 2, 3], 2: [2, 2, 2], 3: [0, 0, 0]}, chosen=1)
    sac = _set(tmp_path / "sac", "sac", {1: [0, 0, 0], 2: [5, 5, 5], 3: [3, 4, 5]}, chosen=3)
    out = tmp_path / "out"
    record = main([str(ref), str(sac), "--out", str(out)])
    row = record["rows"][1]
    assert row["label"] == "SAC" and record["rows"][0]["label"] == "PPO"
    # kept seeds, by episode: [3, 4, 5] - [1, 2, 3] = 2 each, no spread
    assert row["kept_vs_reference"]["diff"] == pytest.approx(2.0)
    assert row["kept_vs_reference"]["sem"] == pytest.approx(0.0, abs=1e-12)
    # by training seed: (0 - 2) + (5 - 2) + (4 - 0), over 3
    assert row["seeds_vs_reference"]["diff"] == pytest.approx(5.0 / 3.0)
    assert row["seeds_vs_reference"]["n"] == 3
    text = (out / "alternatives.md").read_text()
    assert "kept − reference" in text and "reference, PPO" in text and "| SAC | 3 |" in text


def test_sets_that_cannot_be_compared_are_refused(tmp_path):
    ref = _set(tmp_path / "a", "ppo", {1: [1, 2], 2: [1, 1]}, chosen=1)
    other = _set(tmp_path / "b", "sac", {1: [1, 2], 2: [1, 1]}, chosen=1,
                 env="iceenvs/Convergence-v0")
    for argv in ([str(ref), str(other)], [str(ref), str(tmp_path)],
                 [str(ref), str(ref), "--labels", "one"]):
        with pytest.raises(SystemExit):
            main([*argv, "--out", str(tmp_path / "out")])
