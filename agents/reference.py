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

ShipNavigation-v1's is a waypoint student's run instead
(:mod:`agents.waypoints`: ``student.zip``, ``waypoints.json``,
``command.txt``, ``training.yaml``): it decides every 10 s from the
environment's costmap and follows its waypoints by pure pursuit, so it
reads the environment it plays (:func:`load_reference` with
``environment=``, made by :func:`reference_env`); ``agents.leaderboard
--trained``, ``agents.benchmark`` and ``agents.frames`` take its folder,
``agents.evaluate`` and ``agents.train --init-from`` do not.

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
           "REFERENCE_DIR", "MAX_BYTES", "KEPT_FILES", "reference_dir", "is_reference",
           "reference_env", "load_reference", "drop_optimizer_states"]

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
              "training.yaml", "pretrain.yaml", "student.zip", "waypoints.json", "finetune.json")


def reference_dir(env_id: str, root: str | Path | None = None) -> Path:
    """``docs/agents/reference/<env-name>`` of an environment id (under
    ``root`` instead of :data:`REFERENCE_DIR` when given)."""
    return Path(REFERENCE_DIR if root is None else root) / env_id.split("/")[-1]


def is_reference(folder: str | Path) -> bool:
    """Whether ``folder`` holds an agent: a model of :mod:`agents.train`
    (``model.zip``) or a waypoint student (``student.zip``)."""
    from .waypoint_follower import STUDENT

    folder = Path(folder)
    return (folder / "model.zip").is_file() or (folder / STUDENT).is_file()


def _folder(env: str, root: str | Path | None) -> Path:
    folder = reference_dir(env, root)
    if not is_reference(folder):
        base = Path(REFERENCE_DIR if root is None else root)
        have = sorted(p.name for p in base.glob("*") if is_reference(p))
        raise FileNotFoundError(f"no reference agent for {env}; the reference agents: "
                                f"{', '.join(have) or 'none'}")
    return folder


def reference_env(env: str, root: str | Path | None = None, **env_kwargs):
    """The environment the reference agent of ``env`` plays: its id, made
    with the agent's own way of acting and observing
    (:data:`agents.rollouts.AGENT_KWARGS`) over ``env_kwargs``."""
    import gymnasium as gym

    import iceenvs  # noqa: F401  (registers the ids)

    from .rollouts import run_agent_kwargs, run_env_id

    folder = _folder(env, root)
    return gym.make(run_env_id(folder), **{**env_kwargs, **run_agent_kwargs(folder)})


def load_reference(env: str, root: str | Path | None = None, *, environment=None):
    """The reference agent of an environment (``"iceenvs/WindDrift-v0"`` or
    ``"WindDrift-v0"``) as a policy with the baselines' ``predict(obs)``;
    ``env_id`` and ``agent_kwargs`` say which environment it plays and how
    it acts and observes there.

    Most are an :class:`agents.rollouts.TrainedPolicy`, which acts on raw
    observations alone. ShipNavigation-v1's is a waypoint student
    (:class:`agents.waypoint_follower.WaypointStudent`), which reads the
    environment it plays: pass it as ``environment`` (made by
    :func:`reference_env`) and call ``reset(seed)`` with each episode's
    reset, as for the planners.

    Raises
    ------
    FileNotFoundError
        When the id has no reference agent; the message lists those that do.
    ValueError
        When the agent needs ``environment`` and was not given one, or one
        made with other settings than its own.
    """
    from .rollouts import TrainedPolicy, trained_policy
    from .waypoint_follower import student_record

    folder = _folder(env, root)
    if student_record(folder) is None:
        return TrainedPolicy(folder)
    if environment is None:
        raise ValueError(f"the reference agent of {env} is a waypoint student: it reads the "
                         f"environment it plays; pass environment=reference_env({env!r})")
    return trained_policy(folder, environment)


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
