"""The reference agents: one trained agent per environment id, kept in the
repository, and the seeds that keep their evaluation apart from their
training and tuning.

A reference agent is a run directory of :mod:`agents.train` (the best of
its training seeds) under ``docs/agents/reference/<env-name>/``, with only
what playing it needs: ``model.zip``, ``vecnormalize.pkl``,
``hyperparams.yaml``, ``args.yaml``, ``command.txt`` and ``training.yaml``,
each directory under :data:`MAX_BYTES`. Every command that takes a run
directory takes one (``agents.evaluate``, ``agents.leaderboard --trained
NAME=DIR``, ``agents.frames``, ``agents.tasks``, ``agents.train
--init-from``).

Seeds, fixed before any agent was trained or tuned:

- the benchmark plays :data:`EVAL_EPISODES` episodes seeded
  :data:`EVAL_SEED` + k; nothing is trained or tuned on them;
- tuning trains trial n from seed :data:`TUNE_TRAIN_SEED` + n and scores it
  on episodes seeded :data:`TUNE_EVAL_SEED` + k;
- the reference agents train from seeds :data:`TRAIN_SEEDS` (their
  evaluation callback plays episodes seeded 1000 + seed,
  :data:`agents.train.EVAL_SEED_OFFSET`).
"""
from __future__ import annotations

from pathlib import Path

__all__ = ["EVAL_SEED", "EVAL_EPISODES", "TUNE_TRAIN_SEED", "TUNE_EVAL_SEED", "TRAIN_SEEDS",
           "REFERENCE_DIR", "MAX_BYTES", "KEPT_FILES", "reference_dir", "load_reference",
           "drop_optimizer_states"]

#: the benchmark's episodes are seeded EVAL_SEED + k, k < EVAL_EPISODES
EVAL_SEED = 40_000
EVAL_EPISODES = 40
#: tuning trial n trains from TUNE_TRAIN_SEED + n ...
TUNE_TRAIN_SEED = 60_000
#: ... and is scored on episodes seeded TUNE_EVAL_SEED + k
TUNE_EVAL_SEED = 50_000
#: the training seeds of a reference agent
TRAIN_SEEDS = (1, 2, 3)
#: where the reference agents are kept
REFERENCE_DIR = Path(__file__).resolve().parent.parent / "docs" / "agents" / "reference"
#: the largest reference directory kept in the repository [bytes]
MAX_BYTES = 2 * 1024 * 1024
#: the files of a run directory that a reference agent keeps
KEPT_FILES = ("model.zip", "vecnormalize.pkl", "hyperparams.yaml", "args.yaml", "command.txt",
              "training.yaml", "pretrain.yaml")


def reference_dir(env_id: str, root: str | Path | None = None) -> Path:
    """``docs/agents/reference/<env-name>`` of an environment id (under
    ``root`` instead of :data:`REFERENCE_DIR` when given)."""
    return Path(REFERENCE_DIR if root is None else root) / env_id.split("/")[-1]


def load_reference(env: str, root: str | Path | None = None):
    """The reference agent of an environment (``"iceenvs/WindDrift-v0"`` or
    ``"WindDrift-v0"``) as a :class:`agents.rollouts.TrainedPolicy`: its
    ``predict(obs)`` acts on raw observations, ``env_id`` and
    ``agent_kwargs`` say which environment it plays and how it acts and
    observes there.

    Raises
    ------
    FileNotFoundError
        When the id has no reference agent; the message lists those that do.
    """
    from .rollouts import TrainedPolicy

    folder = reference_dir(env, root)
    if not (folder / "model.zip").is_file():
        base = Path(REFERENCE_DIR if root is None else root)
        have = sorted(p.name for p in base.glob("*") if (p / "model.zip").is_file())
        raise FileNotFoundError(f"no reference agent for {env}; the reference agents: "
                                f"{', '.join(have) or 'none'}")
    return TrainedPolicy(folder)


def drop_optimizer_states(model_zip: Path, algo: str) -> int:
    """Save the model in ``model_zip`` again without its optimisers' moments
    (Adam's running averages: as large as the networks, twice over, and not
    needed to play); returns the bytes saved. Fine-tuning such a model
    starts the moments afresh. SAC's six networks with their moments pass
    :data:`MAX_BYTES`; without them they do not."""
    from .train import algo_class

    model_zip = Path(model_zip)
    before = model_zip.stat().st_size
    model = algo_class(algo).load(model_zip, device="cpu")
    for holder in (model.policy, getattr(model.policy, "actor", None),
                   getattr(model.policy, "critic", None), model):
        for name in ("optimizer", "ent_coef_optimizer"):
            optimizer = getattr(holder, name, None) if holder is not None else None
            if optimizer is not None:
                optimizer.state.clear()
    model.save(model_zip)
    return before - model_zip.stat().st_size
