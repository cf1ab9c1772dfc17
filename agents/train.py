"""Train an agent on an environment of the suite.

    python -m agents.train --env iceenvs/Convergence-v0 --algo ppo [--timesteps N]
        [--seed S] [--n-envs K] [--out DIR] [--force] [--eval-freq F]
        [--eval-episodes E] [--hyperparams key=value ...] [--env-kwargs key=value ...]
        [--minutes M]

``main`` runs named steps: parse and check the arguments → read the
hyperparameters (``agents/hyperparams/<algo>.yaml``, the env's entry over
``default``, then ``--hyperparams`` overrides, then ``--env-kwargs`` over
``env_kwargs``) → refuse an existing non-empty run directory without
``--force`` → check the environment arguments on one environment in
this process (``gymnasium.make`` and one ``reset``; a bad keyword exits
with status 2 and the environment's message, before anything is written)
→ prepare the run directory → save the configuration → make the
environments → make the model → make the callbacks → learn → save the
model and the normalisation statistics.

A start that fails before learning begins (making the environments, the
model or the callbacks) leaves no half-written run directory: a directory
this call created is removed, and in a directory that existed before
(``--force``) the artefacts this call wrote are removed; the error is
raised again. An error while learning loses nothing learnt: the model so
far is saved as the checkpoint at its number of steps (evaluate it as
``RUN_DIR@STEPS``), and the error is raised again. ``--minutes`` stops
learning after that much wall-clock time, counted from the making of the
environments, and saves the model as at the end; a warm start
(:mod:`agents.pretrain`) takes at most its ``share`` of the budget, and a
budget too short for it is refused (exit status 2) with the shortest that
is not.

The run directory (default ``runs/agents/<env-name>_<algo>_<seed>``)
holds ``model.zip``, ``vecnormalize.pkl`` (when the observations or
rewards are normalised), ``hyperparams.yaml`` (resolved),
``args.yaml``, ``command.txt``, ``checkpoints/``, ``eval/``,
``metrics.csv`` (physics metrics per training episode) and ``logs/``
(SB3's ``progress.csv``; TensorBoard events when tensorboard is
installed).
"""
from __future__ import annotations

import argparse
import copy
import importlib.util
import inspect
import math
import shlex
import shutil
import sys
import time
from pathlib import Path

import numpy as np
import yaml

from .runs import BEST_STATS, checkpoint_paths, checkpoint_paths_checked

__all__ = ["ALGOS", "HYPERPARAMS_DIR", "SPECIAL_KEYS", "build_parser", "main",
           "read_hyperparams", "valid_keys", "default_run_dir", "checkpoint_paths", "RUN_FILES"]

#: algorithm names of the command line → stable-baselines3 class names
ALGOS = {"ppo": "PPO", "sac": "SAC"}
HYPERPARAMS_DIR = Path(__file__).resolve().parent / "hyperparams"
#: hyperparameters that are not arguments of the algorithm's constructor
SPECIAL_KEYS = ("n_envs", "n_timesteps", "policy", "normalize", "env_kwargs", "pretrain")
#: constructor arguments the trainer sets itself
_RESERVED = {"self", "policy", "env", "seed", "verbose", "device", "tensorboard_log",
             "_init_setup_model"}
#: model artefacts that --force removes from an existing run directory
RUN_FILES = ("model.zip", "vecnormalize.pkl", "hyperparams.yaml", "args.yaml", "command.txt",
             "training.yaml", "pretrain.yaml", "metrics.csv", "checkpoints", "eval", "logs",
             "evaluation.md", "evaluation.json", "evaluation.png")
#: the evaluation environment is seeded this far from the training seed
EVAL_SEED_OFFSET = 1000


def algo_class(algo: str):
    """The stable-baselines3 class of an algorithm name (``"ppo"``, ``"sac"``)."""
    import stable_baselines3

    return getattr(stable_baselines3, ALGOS[algo])


def valid_keys(algo: str) -> list[str]:
    """Hyperparameter names accepted for ``algo``: :data:`SPECIAL_KEYS` and the
    constructor arguments of the SB3 class (except those the trainer sets)."""
    params = inspect.signature(algo_class(algo).__init__).parameters
    return sorted(set(SPECIAL_KEYS) | (set(params) - _RESERVED))


def default_run_dir(env_id: str, algo: str, seed: int) -> Path:
    """``runs/agents/<env-name>_<algo>_<seed>`` (relative to the working directory)."""
    return Path("runs") / "agents" / f"{env_id.split('/')[-1]}_{algo}_{seed}"


# -- step 1: arguments -------------------------------------------------------------------
def build_parser(prog: str = "python -m agents.train") -> argparse.ArgumentParser:
    """The command-line parser (env ids and algorithms as choices)."""
    from iceenvs import ENV_IDS

    from .envs import VECTORIZATIONS, registered_env_id

    p = argparse.ArgumentParser(prog=prog,
                                description="Train a stable-baselines3 agent on an iceenvs "
                                            "environment.")
    p.add_argument("--env", required=True, type=registered_env_id, metavar="ID",
                   help="a registered environment id: " + ", ".join(ENV_IDS)
                        + ", or one registered by your own code")
    p.add_argument("--algo", required=True, choices=sorted(ALGOS),
                   help="algorithm: " + ", ".join(sorted(ALGOS)))
    p.add_argument("--timesteps", type=int, default=None,
                   help="total environment steps (default: n_timesteps of the YAML)")
    p.add_argument("--seed", type=int, default=0, help="random seed (default 0)")
    p.add_argument("--n-envs", type=int, default=None,
                   help="parallel environments (default: n_envs of the YAML)")
    p.add_argument("--out", type=Path, default=None,
                   help="run directory (default runs/agents/<env-name>_<algo>_<seed>)")
    p.add_argument("--force", action="store_true",
                   help="overwrite the artefacts of an existing run directory")
    p.add_argument("--eval-freq", type=int, default=25_000,
                   help="evaluate every this many steps, all envs together (0: never)")
    p.add_argument("--eval-episodes", type=int, default=5,
                   help="episodes per evaluation (default 5)")
    p.add_argument("--save-freq", type=int, default=50_000,
                   help="checkpoint every this many steps, all envs together (0: never)")
    p.add_argument("--conf", type=Path, default=None, metavar="FILE",
                   help="a YAML file whose entry for the id (such as a study's best.yaml) "
                        "takes the place of its entry in agents/hyperparams/<algo>.yaml; a bare "
                        "name not found here is one of agents/hyperparams/ (ppo-costmap.yaml)")
    p.add_argument("--hyperparams", nargs="+", default=[], metavar="KEY=VALUE",
                   help="override hyperparameters; VALUE is YAML, KEY may be dotted "
                        "(env_kwargs.n_floes=50)")
    p.add_argument("--env-kwargs", nargs="+", default=[], metavar="KEY=VALUE",
                   help="gymnasium.make arguments of the environment, set over the YAML's "
                        "env_kwargs and --hyperparams env_kwargs (VALUE is YAML, e.g. "
                        "n_floes=40); checked on one environment before the run starts")
    p.add_argument("--vectorization", choices=VECTORIZATIONS, default="auto",
                   help="how the environments are stepped: native (the environment's own "
                        "vector environment), subproc (a process each), dummy (one after the "
                        "other here); auto (default): for several, native where the environment "
                        "has one, else subproc; dummy for one")
    p.add_argument("--minutes", type=float, default=None,
                   help="stop after this much wall-clock time, from the making of the "
                        "environments and warm start included, and save the model as at the "
                        "end (default: no limit); a warm start takes at most its share "
                        "(pretrain share, default 0.5) and a budget too short for it is "
                        "refused")
    p.add_argument("--init-from", default=None, metavar="RUN_DIR[@STEPS|@best]",
                   help="start from the network (and optimiser) and normalisation statistics of "
                        "a run directory or a reference agent (docs/agents/reference/NAME): its "
                        "final model, its checkpoint at STEPS steps, or its evaluation's best "
                        "model; trains --timesteps more under this run's hyperparameters "
                        "(fine-tuning; resuming is the same with the run's own). No warm start")
    p.add_argument("--no-progress", action="store_true", help="hide the progress bar")
    p.add_argument("--verbose", type=int, default=0, help="SB3 verbosity (0, 1, 2)")
    return p


def parse_args(parser: argparse.ArgumentParser, argv: list[str]) -> argparse.Namespace:
    """Parse and check the arguments (errors exit with status 2)."""
    args = parser.parse_args(argv)
    for name in ("timesteps", "n_envs"):
        value = getattr(args, name)
        if value is not None and value < 1:
            parser.error(f"--{name.replace('_', '-')} must be >= 1, got {value}")
    for name in ("eval_freq", "save_freq"):
        if getattr(args, name) < 0:
            parser.error(f"--{name.replace('_', '-')} must be >= 0")
    if args.eval_episodes < 1:
        parser.error("--eval-episodes must be >= 1")
    if args.minutes is not None and not (math.isfinite(args.minutes) and args.minutes > 0):
        parser.error(f"--minutes must be a positive number, got {args.minutes}")
    if args.vectorization == "native":
        from .envs import has_native_vector_env

        if not has_native_vector_env(args.env):
            parser.error(f"--vectorization native: {args.env} has no native vector environment "
                         f"(its registration has no vector_entry_point); use subproc or dummy")
    if args.init_from is not None:
        from .runs import trained_argument

        try:
            _, run_dir, steps = trained_argument(f"init={args.init_from}", args.env)
            checkpoint_paths_checked(run_dir, steps)
        except (ValueError, FileNotFoundError) as err:
            parser.error(f"--init-from: {err}")
        with open(Path(run_dir) / "args.yaml") as fh:
            trained_with = yaml.safe_load(fh).get("algo")
        if trained_with != args.algo:
            parser.error(f"--init-from {args.init_from}: the run was trained with "
                         f"{trained_with}, not {args.algo}")
    if args.out is None:
        args.out = default_run_dir(args.env, args.algo, args.seed)
    return args


# -- step 2: hyperparameters and environment arguments ----------------------------------------
def read_hyperparams(algo: str, env_id: str, overrides=(), *, timesteps: int | None = None,
                     n_envs: int | None = None, env_kwargs=(), conf: Path | None = None) -> dict:
    """The resolved hyperparameters of a run.

    Parameters
    ----------
    algo : str
        ``"ppo"`` or ``"sac"``.
    env_id : str
        Environment id; its YAML entry replaces the ``default`` entry key
        by key.
    overrides : iterable of str
        ``key=value`` strings (value parsed as YAML; dotted keys set one
        entry of a mapping such as ``env_kwargs``).
    timesteps, n_envs : int, optional
        Override ``n_timesteps`` and ``n_envs``.
    env_kwargs : iterable of str
        ``key=value`` strings (``--env-kwargs``) set over ``env_kwargs``
        after ``overrides`` (:func:`agents.envs.parse_key_values`).
    conf : path, optional
        A YAML file with an entry for ``env_id`` (such as a study's
        ``best.yaml``, :mod:`agents.tune`) that takes the place of the id's
        entry in ``agents/hyperparams/<algo>.yaml``.

    Returns
    -------
    dict

    Raises
    ------
    ValueError
        For a malformed override, an unknown key (the message lists the
        valid ones) or an unknown ``policy_kwargs.features_extractor_class``.
        The environment arguments are not checked here
        (:func:`agents.envs.check_env_kwargs` does).
    """
    from .envs import parse_key_values

    with open(HYPERPARAMS_DIR / f"{algo}.yaml") as fh:
        table = yaml.safe_load(fh)
    hp = copy.deepcopy(table.get("default", {}))
    hp.update(copy.deepcopy(table.get(env_id, {}) if conf is None else read_conf(conf, env_id)))
    hp = parse_key_values(overrides, into=hp, option="--hyperparams")
    if hp.get("env_kwargs") is not None and not isinstance(hp["env_kwargs"], dict):
        raise ValueError(f"hyperparameter env_kwargs must be a mapping, got "
                         f"{hp['env_kwargs']!r}")
    env_kwargs = list(env_kwargs)
    if env_kwargs:
        hp["env_kwargs"] = parse_key_values(env_kwargs, into=hp.get("env_kwargs") or {},
                                            option="--env-kwargs")
    if timesteps is not None:
        hp["n_timesteps"] = int(timesteps)
    if n_envs is not None:
        hp["n_envs"] = int(n_envs)
    valid = valid_keys(algo)
    unknown = sorted(set(hp) - set(valid))
    if unknown:
        raise ValueError(f"unknown hyperparameters {unknown} for {algo}; valid keys: "
                         f"{', '.join(valid)}")
    for key in ("n_envs", "n_timesteps"):
        if not isinstance(hp.get(key), int) or hp[key] < 1:
            raise ValueError(f"hyperparameter {key} must be an integer >= 1, got "
                             f"{hp.get(key)!r}")
    policy_kwargs = hp.get("policy_kwargs") or {}
    if isinstance(policy_kwargs, dict) and policy_kwargs.get("features_extractor_class"):
        from .extractors import extractor_class

        extractor_class(policy_kwargs["features_extractor_class"])    # a known name
    from .pretrain import pretrain_settings

    pretrain = pretrain_settings(hp.pop("pretrain", None))
    if pretrain is not None:
        from .baselines import baseline_names

        if algo != "ppo":
            raise ValueError(f"hyperparameter pretrain: warm starts are made for ppo, not {algo}")
        teachers = baseline_names(env_id)
        if pretrain["teacher"] not in teachers:
            raise ValueError(f"hyperparameter pretrain: unknown teacher {pretrain['teacher']!r} "
                             f"for {env_id}; valid: {', '.join(teachers)}")
        hp["pretrain"] = pretrain
    hp.setdefault("policy", "MlpPolicy")
    hp.setdefault("env_kwargs", {})
    return hp


def read_conf(path: Path, env_id: str) -> dict:
    """The entry of ``env_id`` in the YAML file ``path`` (``--conf``); a bare
    file name that is not a file here names one of ``agents/hyperparams/``
    (``--conf ppo-costmap.yaml``)."""
    path = Path(path)
    if not path.is_file() and len(path.parts) == 1 and (HYPERPARAMS_DIR / path).is_file():
        path = HYPERPARAMS_DIR / path
    try:
        with open(path) as fh:
            table = yaml.safe_load(fh)
    except (OSError, yaml.YAMLError) as err:
        raise ValueError(f"--conf {path}: cannot read it as YAML: {err}") from None
    if not isinstance(table, dict) or not isinstance(table.get(env_id), dict):
        keys = ", ".join(map(str, table)) if isinstance(table, dict) else "none"
        raise ValueError(f"--conf {path} has no entry for {env_id} (its entries: {keys})")
    return table[env_id]


def _schedule(value):
    """A learning rate: a float, or ``"lin_<x>"`` for a linear decay from x to 0."""
    if isinstance(value, str) and value.startswith("lin_"):
        start = float(value[4:])

        def linear(progress_remaining: float) -> float:
            return progress_remaining * start

        return linear
    return float(value)


def algo_kwargs(hp: dict) -> dict:
    """Constructor arguments of the algorithm from resolved hyperparameters
    (learning-rate schedules, activation names, feature extractor names of
    :data:`agents.extractors.EXTRACTORS`, ``train_freq`` lists)."""
    import torch

    kw = {k: v for k, v in hp.items() if k not in SPECIAL_KEYS}
    if "learning_rate" in kw:
        kw["learning_rate"] = _schedule(kw["learning_rate"])
    pk = dict(kw.get("policy_kwargs") or {})
    if isinstance(pk.get("activation_fn"), str):
        pk["activation_fn"] = getattr(torch.nn, {"tanh": "Tanh", "relu": "ReLU",
                                                 "elu": "ELU"}.get(pk["activation_fn"].lower(),
                                                                    pk["activation_fn"]))
    if isinstance(pk.get("features_extractor_class"), str):
        from .extractors import extractor_class

        pk["features_extractor_class"] = extractor_class(pk["features_extractor_class"])
    if pk:
        kw["policy_kwargs"] = pk
    if isinstance(kw.get("train_freq"), list):
        kw["train_freq"] = tuple(kw["train_freq"])
    return kw


def normalize_kwargs(hp: dict) -> dict | None:
    """Keyword arguments of :class:`VecNormalize` (``None``: no normalisation);
    its discount defaults to the algorithm's ``gamma``."""
    norm = hp.get("normalize", False)
    if not norm:
        return None
    kw = {} if norm is True else dict(norm)
    if "gamma" in hp:
        kw.setdefault("gamma", hp["gamma"])
    return kw


# -- step 3: the run directory -------------------------------------------------------------
def _first_missing(path: Path) -> Path | None:
    """The outermost directory of ``path`` (itself included) that does not
    exist yet, i.e. the one that creating ``path`` would create; ``None``
    when ``path`` exists."""
    missing = None
    for candidate in (path, *path.parents):
        if candidate.exists():
            break
        missing = candidate
    return missing


def _remove_run_files(run_dir: Path) -> None:
    for name in RUN_FILES:
        path = run_dir / name
        if path.is_dir() and not path.is_symlink():
            shutil.rmtree(path)
        elif path.exists() or path.is_symlink():
            path.unlink()


def discard_run_dir(run_dir: Path, created: Path | None) -> None:
    """Undo :func:`prepare_run_dir` and what followed after a failed start.

    ``created`` is the outermost directory the preparation created
    (:func:`_first_missing` before it): the run directory is removed
    entirely and so are the created parents it leaves empty. When the run
    directory existed before (``created`` is ``None``), only the
    artefacts of :data:`RUN_FILES` are removed; other files stay."""
    run_dir = Path(run_dir)
    if created is None:
        if run_dir.is_dir():
            _remove_run_files(run_dir)
        return
    shutil.rmtree(run_dir, ignore_errors=True)
    parent = run_dir.parent
    created = Path(created)
    while parent == created or created in parent.parents:
        try:
            parent.rmdir()          # only when empty
        except OSError:
            break
        if parent == created:
            break
        parent = parent.parent


def check_run_dir(parser: argparse.ArgumentParser, args: argparse.Namespace) -> None:
    """Refuse (exit status 2) an ``--out`` that is a file, or an existing
    non-empty directory without ``--force``; touches nothing."""
    out = Path(args.out)
    if out.exists() and not out.is_dir():
        parser.error(f"--out {out} exists and is not a directory")
    if out.is_dir() and any(out.iterdir()) and not args.force:
        parser.error(f"run directory {out} exists and is not empty; pass --force to "
                     f"overwrite it or choose another --out")


def prepare_run_dir(parser: argparse.ArgumentParser, args: argparse.Namespace) -> Path:
    """Create the run directory; an existing non-empty one is refused
    unless ``--force``, which removes the artefacts of the previous run."""
    check_run_dir(parser, args)
    out = Path(args.out)
    if out.is_dir() and any(out.iterdir()):
        _remove_run_files(out)
    out.mkdir(parents=True, exist_ok=True)
    return out


# -- step 4: configuration ---------------------------------------------------------------
def save_config(run_dir: Path, args: argparse.Namespace, hp: dict, argv: list[str]) -> None:
    """Write ``hyperparams.yaml``, ``args.yaml`` and ``command.txt``."""
    with open(run_dir / "hyperparams.yaml", "w") as fh:
        yaml.safe_dump(hp, fh, sort_keys=True)
    plain = {k: (str(v) if isinstance(v, Path) else v) for k, v in vars(args).items()}
    with open(run_dir / "args.yaml", "w") as fh:
        yaml.safe_dump(plain, fh, sort_keys=True)
    (run_dir / "command.txt").write_text(
        shlex.join([sys.executable, "-m", "agents.train", *argv]) + "\n")


# -- step 5: environments -------------------------------------------------------------------
def make_envs(args: argparse.Namespace, hp: dict):
    """The training stack and a one-env evaluation stack (seeded
    ``seed + EVAL_SEED_OFFSET``; normalisation frozen, synced from training
    by :class:`EvalCallback`)."""
    from .envs import make_vec_env

    norm = normalize_kwargs(hp)
    env = make_vec_env(args.env, n_envs=hp["n_envs"], seed=args.seed,
                       env_kwargs=hp["env_kwargs"], normalize=norm,
                       vectorization=args.vectorization)
    eval_env = None
    if args.eval_freq > 0:
        try:
            eval_env = make_vec_env(args.env, n_envs=1, seed=args.seed + EVAL_SEED_OFFSET,
                                    env_kwargs=hp["env_kwargs"], normalize=norm,
                                    training=False)
        except BaseException:
            env.close()
            raise
    return env, eval_env


# -- step 6: model ---------------------------------------------------------------------------
def make_model(args: argparse.Namespace, hp: dict, env, run_dir: Path):
    """The SB3 model, seeded, on the CPU, logging to ``run_dir/logs``
    (CSV; TensorBoard when importable; stdout when ``--verbose``)."""
    from stable_baselines3.common.logger import configure

    model = algo_class(args.algo)(hp["policy"], env, seed=args.seed, device="cpu",
                                  verbose=args.verbose, **algo_kwargs(hp))
    formats = ["csv"]
    if importlib.util.find_spec("tensorboard") is not None:
        formats.append("tensorboard")
    if args.verbose:
        formats.append("stdout")
    model.set_logger(configure(str(run_dir / "logs"), formats))
    return model


# -- step 7: callbacks -----------------------------------------------------------------------
def make_callbacks(args: argparse.Namespace, hp: dict, eval_env, run_dir: Path,
                   started: float | None = None) -> list:
    """Checkpoints, evaluation, physics metrics and the progress bar; the
    ``--minutes`` budget counts from ``started`` (a ``time.perf_counter``
    value; default: the start of learning)."""
    from stable_baselines3.common.callbacks import CheckpointCallback, EvalCallback

    from .callbacks import (PhysicsMetricsCallback, SaveNormalizationOnBest, TimeBudgetCallback,
                            TqdmCallback)

    n_envs = hp["n_envs"]
    callbacks = []
    if args.save_freq > 0:
        callbacks.append(CheckpointCallback(max(args.save_freq // n_envs, 1),
                                            str(run_dir / "checkpoints"), name_prefix="model",
                                            save_vecnormalize=True))
    if eval_env is not None:
        callbacks.append(EvalCallback(eval_env, n_eval_episodes=args.eval_episodes,
                                      eval_freq=max(args.eval_freq // n_envs, 1),
                                      log_path=str(run_dir / "eval"),
                                      best_model_save_path=str(run_dir / "eval"),
                                      callback_on_new_best=SaveNormalizationOnBest(
                                          run_dir / "eval" / BEST_STATS),
                                      deterministic=True, verbose=args.verbose))
    callbacks.append(PhysicsMetricsCallback(args.env, run_dir / "metrics.csv"))
    callbacks.append(TqdmCallback(hp["n_timesteps"], disable=args.no_progress))
    if args.minutes is not None:
        callbacks.append(TimeBudgetCallback(args.minutes, started=started))
    return callbacks


# -- step 7b: warm start ------------------------------------------------------------------------
def warm_start(args: argparse.Namespace, hp: dict, model, env, run_dir: Path,
               started: float | None = None) -> dict | None:
    """Fit the policy to a planner's decisions when ``hp["pretrain"]`` asks
    for it (:mod:`agents.pretrain`), write ``pretrain.yaml`` and, when
    checkpointing, the checkpoint at 0 steps (the clone before PPO).

    Under ``--minutes`` the warm start ends by its ``share`` of the budget,
    counted from ``started`` (a ``time.perf_counter`` value; default now);
    a budget too short for one demonstration is refused with the shortest
    that holds one (:class:`agents.pretrain.BudgetTooShort`)."""
    if not hp.get("pretrain"):
        return None
    if args.init_from is not None:
        print("no warm start: the run starts from --init-from", flush=True)
        return None
    from .dagger import dagger
    from .pretrain import COLLECT_PART, BudgetTooShort, pretrain

    settings = hp["pretrain"]
    started = time.perf_counter() if started is None else started
    deadline = None
    plan = f"warm start: {settings['episodes']} episodes of {settings['teacher']}"
    if args.minutes is not None:
        budget = 60.0 * args.minutes
        deadline = started + settings["share"] * budget
        plan = (f"warm start: up to {settings['episodes']} episodes of {settings['teacher']}, "
                f"within {settings['share'] * budget:.0f} s ({settings['share']:.0%}) of the "
                f"{args.minutes:g}-minute budget; PPO gets the rest")
    print(plan, flush=True)
    try:
        report = pretrain(model, env, args.env, hp["env_kwargs"], settings,
                          gamma=float(hp.get("gamma", 0.99)), progress=not args.no_progress,
                          deadline=deadline, rounds=dagger)
    except BudgetTooShort as err:
        # the share must hold the set-up so far and one episode, in COLLECT_PART of it
        needed = (time.perf_counter() - started) / COLLECT_PART / settings["share"]
        raise BudgetTooShort(f"--minutes {args.minutes:g} is too short for the warm start: "
                             f"{err}; give at least --minutes {math.ceil(needed / 6) / 10:g}, "
                             f"or train without it (--hyperparams pretrain=null)") from None
    if args.minutes is not None:
        report["budget_seconds"] = round(60.0 * args.minutes, 1)
    with open(run_dir / "pretrain.yaml", "w") as fh:
        yaml.safe_dump(report, fh, sort_keys=True)
    if args.save_freq > 0:
        save(model, env, run_dir, 0)      # the clone before PPO: RUN_DIR@0
    print(f"warm start from {report['teacher']}: {report['episodes_sailed']} of "
          f"{report['episodes']} episodes, {report['decisions']} decisions in "
          f"{report['collect_seconds']:.0f} s, fitted in {report['fit_seconds']:.0f} s; action "
          f"mean squared error {report['action_mse']:.3g} (variance "
          f"{report['action_variance']:.3g})", flush=True)
    return report


# -- step 7c: start from a trained network ------------------------------------------------------
class InitMismatch(ValueError):
    """``--init-from`` names a model whose network or observations do not fit the run."""


def init_from(args: argparse.Namespace, model, env) -> dict | None:
    """With ``--init-from RUN_DIR[@STEPS|@best]``: load that model's network
    and optimiser into ``model`` and its normalisation statistics into the
    training stack (the run then trains its own timesteps from there).

    Raises
    ------
    InitMismatch
        When the saved network or statistics do not have this run's shapes
        (another observation, action or architecture)."""
    if args.init_from is None:
        return None
    import pickle

    from .runs import trained_argument

    _, source, steps = trained_argument(f"init={args.init_from}", args.env)
    model_path, stats_path = checkpoint_paths_checked(source, steps)
    try:
        model.set_parameters(str(model_path), exact_match=True, device="cpu")
    except (ValueError, RuntimeError, KeyError) as err:
        lines = [line.strip() for line in str(err).splitlines() if line.strip()]
        first = next((line for line in lines if "mismatch" in line), lines[0] if lines else "")
        more = sum("mismatch" in line for line in lines) - 1
        raise InitMismatch(f"--init-from {args.init_from}: its network does not fit this run's "
                           f"(another observation, action or net_arch?): {first}"
                           + (f" (and {more} more)" if more > 0 else "")) from None
    vec_normalize = model.get_vec_normalize_env()
    stats = "none"
    if vec_normalize is not None and stats_path.is_file():
        with open(stats_path, "rb") as fh:
            saved = pickle.load(fh)
        mine, theirs = vec_normalize.obs_rms, saved.obs_rms
        if getattr(mine, "mean", None) is not None and \
                np.shape(mine.mean) != np.shape(getattr(theirs, "mean", None)):
            raise InitMismatch(f"--init-from {args.init_from}: its observation statistics have "
                               f"shape {np.shape(theirs.mean)}, this run observes "
                               f"{np.shape(mine.mean)}")
        vec_normalize.obs_rms, vec_normalize.ret_rms = theirs, saved.ret_rms
        stats = str(stats_path.name)
    elif vec_normalize is not None:
        stats = "fresh (the source has none)"
    print(f"starting from {model_path} (normalisation statistics: {stats})", flush=True)
    return dict(source=str(args.init_from), model=str(model_path), statistics=stats)


# -- step 8: learn and save --------------------------------------------------------------------
def learn(model, hp: dict, callbacks: list) -> None:
    """Run ``model.learn`` for ``n_timesteps``."""
    from stable_baselines3.common.callbacks import CallbackList

    model.learn(total_timesteps=hp["n_timesteps"], callback=CallbackList(callbacks),
                progress_bar=False)


def stop_reason(callbacks: list, model, hp: dict) -> str:
    """Why learning ended: ``"steps"`` (all ``n_timesteps``) or the reason
    a callback stopped it (the time budget's)."""
    for callback in callbacks:
        if getattr(callback, "reason", None):
            return callback.reason
    return "steps" if model.num_timesteps >= hp["n_timesteps"] else "a callback"


def host_info() -> dict:
    """The machine a run trained on: CPU, logical CPUs, torch threads,
    Python and the platform."""
    import os
    import platform

    import torch

    cpu = platform.processor() or platform.machine()
    try:
        with open("/proc/cpuinfo") as fh:
            cpu = next((line.split(":", 1)[1].strip() for line in fh
                        if line.startswith("model name")), cpu)
    except OSError:
        pass
    return dict(cpu=cpu, logical_cpus=os.cpu_count(), torch_threads=torch.get_num_threads(),
                python=platform.python_version(), platform=platform.platform())


def save_summary(run_dir: Path, hp: dict, model, *, started: float, learn_started: float,
                 reason: str, init: dict | None, start_utc: str) -> dict:
    """Write ``training.yaml``: the steps trained and planned, why learning
    ended, the wall time (from the making of the environments; learning
    alone), the host, the source commit and the model started from."""
    from physics.provenance import source_commit

    now = time.perf_counter()
    summary = dict(steps=int(model.num_timesteps), planned_steps=int(hp["n_timesteps"]),
                   stopped_by=reason, wall_seconds=round(now - started, 1),
                   learn_seconds=round(now - learn_started, 1), started_utc=start_utc,
                   host=host_info(), commit=source_commit(), init_from=init)
    with open(run_dir / "training.yaml", "w") as fh:
        yaml.safe_dump(summary, fh, sort_keys=False)
    return summary


def save(model, env, run_dir: Path, steps: int | None = None) -> None:
    """Write ``model.zip`` and, when normalising, ``vecnormalize.pkl``; with
    ``steps``, the checkpoint at that many steps instead
    (:func:`checkpoint_paths`)."""
    from stable_baselines3.common.vec_env import VecNormalize

    model_path, stats_path = checkpoint_paths(run_dir, steps)
    model_path.parent.mkdir(exist_ok=True)
    model.save(model_path)
    if isinstance(env, VecNormalize):
        env.save(str(stats_path))


def _close(*things) -> None:
    for thing in things:
        if thing is not None:
            thing.close()


def main(argv: list[str] | None = None, prog: str = "python -m agents.train") -> Path:
    """Command-line entry point (``prog``: the command's name in the help);
    returns the run directory."""
    from .envs import check_env_kwargs
    from .pretrain import BudgetTooShort

    argv = list(sys.argv[1:] if argv is None else argv)
    parser = build_parser(prog)
    args = parse_args(parser, argv)
    try:
        hp = read_hyperparams(args.algo, args.env, args.hyperparams, timesteps=args.timesteps,
                              n_envs=args.n_envs, env_kwargs=args.env_kwargs, conf=args.conf)
    except ValueError as err:
        parser.error(str(err))
    check_run_dir(parser, args)
    try:
        check_env_kwargs(args.env, hp["env_kwargs"], seed=args.seed)
    except ValueError as err:
        parser.error(str(err))
    created = _first_missing(Path(args.out))
    run_dir = prepare_run_dir(parser, args)

    env = eval_env = model = None
    try:
        save_config(run_dir, args, hp, argv)

        import torch

        torch.set_num_threads(1)
        started = time.perf_counter()
        start_utc = time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime())
        env, eval_env = make_envs(args, hp)
        model = make_model(args, hp, env, run_dir)
        init = init_from(args, model, env)
        callbacks = make_callbacks(args, hp, eval_env, run_dir,
                                   started=started)
        warm_start(args, hp, model, env, run_dir, started)
    except BaseException as exc:
        _close(env, eval_env, model.logger if model is not None else None)
        discard_run_dir(run_dir, created)
        if isinstance(exc, (BudgetTooShort, InitMismatch)):
            parser.error(str(exc))
        raise
    learn_started = time.perf_counter()
    summary = dict(started=started, learn_started=learn_started, init=init,
                   start_utc=start_utc)
    try:
        try:
            learn(model, hp, callbacks)
        except Exception:
            # nothing learnt is lost: the model so far becomes a checkpoint
            steps = model.num_timesteps
            save(model, env, run_dir, steps)
            save_summary(run_dir, hp, model, reason="an error", **summary)
            print(f"training stopped by an error at {steps} steps; the model so far is saved "
                  f"as its checkpoint (evaluate it as {run_dir}@{steps})", file=sys.stderr)
            raise
        save(model, env, run_dir)
    finally:
        _close(env, eval_env)
    done = save_summary(run_dir, hp, model, reason=stop_reason(callbacks, model, hp), **summary)
    if done["stopped_by"] != "steps":
        print(f"training stopped by {done['stopped_by']} at {done['steps']} of "
              f"{done['planned_steps']} steps ({done['steps'] / done['planned_steps']:.0%}), "
              f"after {done['wall_seconds']:.0f} s", flush=True)
    else:
        print(f"trained {done['steps']} steps in {done['wall_seconds']:.0f} s", flush=True)
    print(f"saved {run_dir / 'model.zip'}")
    return run_dir


if __name__ == "__main__":
    main()
