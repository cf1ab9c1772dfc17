"""Run directories of :mod:`agents.train` and what commands name in them:
the final model, a checkpoint at some steps, or the evaluation callback's
best model (``RUN_DIR``, ``RUN_DIR@STEPS``, ``RUN_DIR@best``). A reference
agent's directory (:mod:`agents.reference`) is a run directory too."""
from __future__ import annotations

from pathlib import Path

import yaml

__all__ = ["BEST", "BEST_STATS", "checkpoint_paths", "checkpoint_paths_checked",
           "run_env_id", "trained_argument"]

#: the checkpoint name of the evaluation callback's best model (``RUN_DIR@best``)
BEST = "best"
#: the normalisation statistics saved with the best model, in ``eval/``
BEST_STATS = "best_vecnormalize.pkl"


def checkpoint_paths(run_dir: Path, steps: int | str | None = None) -> tuple[Path, Path]:
    """(model, normalisation statistics) paths of a run: the final ones
    (``model.zip``, ``vecnormalize.pkl``); with ``steps``, those of the
    checkpoint at that many steps, as the checkpoint callback names them
    (``checkpoints/model_<steps>_steps.zip``,
    ``checkpoints/model_vecnormalize_<steps>_steps.pkl``); with
    ``steps="best"``, the evaluation callback's best model and the
    statistics it was evaluated with (``eval/best_model.zip``,
    ``eval/best_vecnormalize.pkl``)."""
    run_dir = Path(run_dir)
    if steps is None:
        return run_dir / "model.zip", run_dir / "vecnormalize.pkl"
    if steps == BEST:
        return run_dir / "eval" / "best_model.zip", run_dir / "eval" / BEST_STATS
    folder = run_dir / "checkpoints"
    return folder / f"model_{steps}_steps.zip", folder / f"model_vecnormalize_{steps}_steps.pkl"


def checkpoint_paths_checked(run_dir: Path, steps: int | str | None = None) -> tuple[Path, Path]:
    """:func:`checkpoint_paths` of a model that exists.

    Raises
    ------
    FileNotFoundError
        When there is no such model; the message lists the run's checkpoints.
    """
    run_dir = Path(run_dir)
    model, stats = checkpoint_paths(run_dir, steps)
    if not model.is_file():
        saved = sorted(int(p.stem.split("_")[1]) for p in (run_dir / "checkpoints").glob(
            "model_*_steps.zip"))
        if (run_dir / "eval" / "best_model.zip").is_file():
            saved.append(BEST)
        what = ("no model.zip" if steps is None else "no best model (eval/best_model.zip)"
                if steps == BEST else f"no checkpoint at {steps} steps")
        raise FileNotFoundError(f"{run_dir} holds {what}; its checkpoints: "
                                f"{', '.join(map(str, saved)) or 'none'}")
    return model, stats


def run_env_id(run_dir: str | Path) -> str | None:
    """The environment id a run of :mod:`agents.train` (``args.yaml``; None
    when it names none) or a waypoint student's run (its record,
    :func:`agents.waypoint_follower.student_record`) was trained on."""
    from .waypoint_follower import student_record

    student = student_record(run_dir)
    if student is not None:
        return student["settings"]["env_id"]
    with open(Path(run_dir) / "args.yaml") as fh:
        return yaml.safe_load(fh).get("env")


def trained_argument(item: str, env_id: str | None = None) -> tuple[str, str, int | str | None]:
    """``(name, run_dir, checkpoint or None)`` of a ``--trained`` argument
    ``NAME=RUN_DIR``, ``NAME=RUN_DIR@STEPS`` or ``NAME=RUN_DIR@best``: the
    run directory of :mod:`agents.train` (it must hold ``args.yaml``; a
    reference agent's directory is one) or of a waypoint student
    (``student.zip``, :mod:`agents.waypoints`) and, with ``@STEPS``, its
    checkpoint at STEPS steps, with ``@best`` its evaluation callback's
    best model.

    Raises
    ------
    ValueError
        Another form, a directory that is not a run directory, or a run
        trained on another environment than ``env_id`` (when given)."""
    name, sep, target = item.partition("=")
    run_dir, at, steps = target.partition("@")
    if not sep or not name or (at and not (steps.isdigit() or steps == BEST)):
        raise ValueError(f"--trained takes NAME=RUN_DIR, NAME=RUN_DIR@STEPS or "
                         f"NAME=RUN_DIR@best, got {item!r}")
    from .waypoint_follower import student_record

    student = student_record(run_dir)
    if student is not None and at:
        raise ValueError(f"--trained {item}: {run_dir} is a waypoint student's run, which keeps "
                         f"no checkpoints")
    if student is None and not (Path(run_dir) / "args.yaml").is_file():
        raise ValueError(f"--trained {item}: {run_dir} is not an existing run directory of "
                         f"agents.train (no args.yaml) nor a waypoint student's (no student.zip)")
    if env_id is not None:
        trained_on = run_env_id(run_dir)
        if trained_on != env_id:
            raise ValueError(f"--trained {item}: the run was trained on {trained_on}, "
                             f"not {env_id}")
    checkpoint = None if not at else BEST if steps == BEST else int(steps)
    return name, run_dir, checkpoint
