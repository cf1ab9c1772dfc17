"""Tune an algorithm's hyperparameters on an environment with Optuna.

    python -m agents.tune --env iceenvs/Convergence-v0 --algo ppo [--trials 20]
        [--minutes 60] [--trial-timesteps 60000] [--trial-minutes 5]
        [--evaluations 4] [--eval-episodes 8] [--out DIR] [--storage FILE]
        [--worker K] [--hyperparams key=value ...] [--env-kwargs key=value ...]

Each trial draws a set of hyperparameters (:func:`sample_ppo`,
:func:`sample_sac`) over the id's entry of ``agents/hyperparams/<algo>.yaml``
(its environment arguments and whatever the search does not draw), trains a
model for ``--trial-timesteps`` steps (or ``--trial-minutes``), and scores
it ``--evaluations`` times on the way: the mean deterministic return of
``--eval-episodes`` episodes seeded :data:`agents.reference.TUNE_EVAL_SEED`
+ k, the same episodes for every trial and every evaluation, so that trials
are compared paired. Optuna's TPE sampler draws the next trial from the
scores so far; its median pruner stops a trial whose score at an
evaluation is below the median of the earlier trials' at the same point
(after the first :data:`STARTUP_TRIALS` trials and the first evaluation).
A trial's value is its last score.

Tuning seeds are its own: trial n trains from seed
:data:`agents.reference.TUNE_TRAIN_SEED` + n and is scored on episodes
seeded 50000 + k, never on the benchmark's evaluation episodes
(:data:`agents.reference.EVAL_SEED` + k).

The study is written to ``--out`` (default
``docs/agents/studies/<env-name>_<algo>/``) after every trial, so that an
interrupted study loses nothing: ``study.json`` (every trial's parameters,
state, scores at each evaluation, steps and wall time; the best trial; the
parameters' importances; the command, commit, host and budget),
``study.md`` (the same as tables), ``study.png`` (scores per trial and
importances) and ``best.yaml`` (the best trial's hyperparameters as an
entry of ``agents/hyperparams/<algo>.yaml``).

More cores: start the same command in several shells with one
``--storage FILE`` (an Optuna journal file) and a different ``--worker``
each; they share the study, and each writes the record when it ends.
"""
from __future__ import annotations

import argparse
import json
import math
import shlex
import sys
import time
from pathlib import Path

import numpy as np
import yaml

__all__ = ["sample_ppo", "sample_sac", "SAMPLERS", "trial_hyperparams", "STARTUP_TRIALS",
           "build_parser", "main", "study_record", "default_out"]

#: trials run to completion before the pruner may stop one
STARTUP_TRIALS = 3
#: the network sizes the search chooses between
NET_ARCHS = {"small": [64, 64], "medium": [128, 128], "large": [256, 256]}


def sample_ppo(trial) -> dict:
    """PPO hyperparameters drawn by an Optuna ``trial``: rollout length,
    minibatch, epochs, discount, GAE, clipping, learning rate, entropy
    bonus, initial exploration noise and network size."""
    n_steps = trial.suggest_categorical("n_steps", [256, 512, 1024, 2048])
    batch_size = trial.suggest_categorical("batch_size", [64, 128, 256, 512])
    arch = trial.suggest_categorical("net_arch", list(NET_ARCHS))
    return dict(
        n_steps=n_steps,
        batch_size=min(batch_size, n_steps),
        n_epochs=trial.suggest_categorical("n_epochs", [5, 10, 20]),
        gamma=trial.suggest_categorical("gamma", [0.95, 0.98, 0.99, 0.995, 0.999]),
        gae_lambda=trial.suggest_categorical("gae_lambda", [0.9, 0.95, 0.98]),
        clip_range=trial.suggest_categorical("clip_range", [0.1, 0.2, 0.3]),
        learning_rate=trial.suggest_float("learning_rate", 1e-5, 3e-3, log=True),
        ent_coef=trial.suggest_float("ent_coef", 1e-8, 1e-2, log=True),
        policy_kwargs=dict(net_arch=dict(pi=NET_ARCHS[arch], vf=NET_ARCHS[arch]),
                           log_std_init=trial.suggest_float("log_std_init", -3.0, 0.0)),
    )


def sample_sac(trial) -> dict:
    """SAC hyperparameters drawn by an Optuna ``trial``: learning rate,
    minibatch, buffer, discount, target smoothing, updates per step,
    steps before learning and network size."""
    train_freq = trial.suggest_categorical("train_freq", [1, 4, 8])
    arch = trial.suggest_categorical("net_arch", list(NET_ARCHS))
    return dict(
        learning_rate=trial.suggest_float("learning_rate", 1e-5, 3e-3, log=True),
        batch_size=trial.suggest_categorical("batch_size", [64, 128, 256, 512]),
        buffer_size=trial.suggest_categorical("buffer_size", [10_000, 100_000, 1_000_000]),
        gamma=trial.suggest_categorical("gamma", [0.95, 0.98, 0.99, 0.995, 0.999]),
        tau=trial.suggest_categorical("tau", [0.005, 0.01, 0.02, 0.05]),
        train_freq=train_freq,
        gradient_steps=train_freq,
        learning_starts=trial.suggest_categorical("learning_starts", [100, 1000, 5000]),
        policy_kwargs=dict(net_arch=NET_ARCHS[arch],
                           log_std_init=trial.suggest_float("log_std_init", -3.0, 0.0)),
    )


#: the search space of each algorithm
SAMPLERS = {"ppo": sample_ppo, "sac": sample_sac}


def trial_hyperparams(base_hp: dict, drawn: dict) -> dict:
    """A trial's hyperparameters: those drawn over the base entry's, with
    the drawn ``policy_kwargs`` set over the base's key by key, so that what
    the search does not draw (a feature extractor and its arguments) stays."""
    hp = {**base_hp, **drawn}
    if "policy_kwargs" in drawn:
        hp["policy_kwargs"] = {**(base_hp.get("policy_kwargs") or {}), **drawn["policy_kwargs"]}
    return hp


def default_out(env_id: str, algo: str) -> Path:
    """``docs/agents/studies/<env-name>_<algo>`` (relative to the working directory)."""
    return Path("docs") / "agents" / "studies" / f"{env_id.split('/')[-1]}_{algo}"


# -- arguments ------------------------------------------------------------------------------
def build_parser(prog: str = "python -m agents.tune") -> argparse.ArgumentParser:
    from iceenvs import ENV_IDS

    from .envs import VECTORIZATIONS, registered_env_id
    from .train import ALGOS

    p = argparse.ArgumentParser(prog=prog, description="Search an algorithm's hyperparameters "
                                                       "on an iceenvs environment with Optuna.")
    p.add_argument("--env", required=True, type=registered_env_id, metavar="ID",
                   help="a registered environment id: " + ", ".join(ENV_IDS))
    p.add_argument("--algo", required=True, choices=sorted(ALGOS))
    p.add_argument("--trials", type=int, default=20,
                   help="trials of this process (default 20); the study ends at --minutes too")
    p.add_argument("--minutes", type=float, default=None,
                   help="no new trial after this much wall-clock time (default: no limit)")
    p.add_argument("--trial-timesteps", type=int, default=60_000,
                   help="environment steps of a trial (default 60000)")
    p.add_argument("--trial-minutes", type=float, default=None,
                   help="stop a trial after this much wall-clock time (it is then scored "
                        "where it stopped)")
    p.add_argument("--evaluations", type=int, default=4,
                   help="scores per trial, evenly spaced; the pruner reads them (default 4)")
    p.add_argument("--eval-episodes", type=int, default=8,
                   help="episodes per score (default 8)")
    p.add_argument("--n-envs", type=int, default=None,
                   help="parallel environments of a trial (default: n_envs of the YAML)")
    p.add_argument("--vectorization", choices=VECTORIZATIONS, default="auto")
    p.add_argument("--seed", type=int, default=0, help="the sampler's seed (default 0)")
    p.add_argument("--worker", type=int, default=0,
                   help="a process sharing --storage with others: offsets the sampler's seed")
    p.add_argument("--storage", type=Path, default=None, metavar="FILE",
                   help="an Optuna journal file holding the study, shared by several "
                        "processes and resumed by a later call (default: in memory)")
    p.add_argument("--out", type=Path, default=None,
                   help="record directory (default docs/agents/studies/<env-name>_<algo>)")
    p.add_argument("--hyperparams", nargs="+", default=[], metavar="KEY=VALUE",
                   help="fixed hyperparameters, set before the search's draws (which win)")
    p.add_argument("--env-kwargs", nargs="+", default=[], metavar="KEY=VALUE",
                   help="gymnasium.make arguments, over the YAML's env_kwargs")
    p.add_argument("--warm-start", action="store_true",
                   help="start every trial from the warm start of the hyperparameters (their "
                        "pretrain entry: a clone of a baseline), as the id's reference agent "
                        "may; without it the entry is dropped and trials start at random")
    p.add_argument("--no-progress", action="store_true", help="hide the progress bar")
    return p


def parse_args(parser: argparse.ArgumentParser, argv: list[str]) -> argparse.Namespace:
    args = parser.parse_args(argv)
    for name in ("trials", "trial_timesteps", "evaluations", "eval_episodes"):
        if getattr(args, name) < 1:
            parser.error(f"--{name.replace('_', '-')} must be >= 1, got {getattr(args, name)}")
    if args.n_envs is not None and args.n_envs < 1:
        parser.error(f"--n-envs must be >= 1, got {args.n_envs}")
    for name in ("minutes", "trial_minutes"):
        value = getattr(args, name)
        if value is not None and not (math.isfinite(value) and value > 0):
            parser.error(f"--{name.replace('_', '-')} must be a positive number, got {value}")
    if args.out is None:
        args.out = default_out(args.env, args.algo)
    return args


# -- a trial ----------------------------------------------------------------------------------
class _Scorer:
    """Scores a model being trained: the mean deterministic return of the
    tuning episodes, observations normalised with the training stack's
    statistics of the moment."""

    def __init__(self, env_id: str, env_kwargs: dict, episodes: int, seed: int):
        import gymnasium as gym

        self.env = gym.make(env_id, **env_kwargs)
        self.episodes = episodes
        self.seed = seed

    def __call__(self, model) -> float:
        from .observations import as_float32
        from .rollouts import run_episode

        vec_normalize = model.get_vec_normalize_env()

        class Live:
            def reset(self, seed=None):
                pass

            def predict(self, obs, state=None, episode_start=None, deterministic=True):
                obs = as_float32(obs)
                if vec_normalize is not None:
                    obs = as_float32(vec_normalize.normalize_obs(obs))
                return model.predict(obs, deterministic=True)

        returns = [run_episode(self.env, Live(), self.seed + k, None)["ret"]
                   for k in range(self.episodes)]
        return float(np.mean(returns))

    def close(self):
        self.env.close()


def _trial_callback(trial, scorer: _Scorer, every: int, scores: list):
    """An SB3 callback that scores the model every ``every`` steps, reports
    the score to the trial and stops learning when the pruner says so."""
    from stable_baselines3.common.callbacks import BaseCallback

    class Report(BaseCallback):
        pruned = False

        def __init__(self):
            super().__init__(0)
            self.next = every

        def _on_step(self) -> bool:
            if self.num_timesteps < self.next:
                return True
            self.next += every
            score = scorer(self.model)
            scores.append((int(self.num_timesteps), score))
            trial.report(score, len(scores))
            if trial.should_prune():
                self.pruned = True
                return False
            return True

    return Report()


def run_trial(trial, args: argparse.Namespace, base_hp: dict) -> float:
    """Train one trial's model and return its last score (raises
    ``optuna.TrialPruned`` when pruned)."""
    import optuna
    import torch

    from .callbacks import TimeBudgetCallback
    from .envs import make_vec_env
    from .reference import TUNE_EVAL_SEED, TUNE_TRAIN_SEED
    from .train import algo_class, algo_kwargs, normalize_kwargs

    drawn = SAMPLERS[args.algo](trial)
    hp = trial_hyperparams(base_hp, drawn)
    hp["n_timesteps"] = args.trial_timesteps
    seed = TUNE_TRAIN_SEED + trial.number
    trial.set_user_attr("train_seed", seed)
    torch.set_num_threads(1)
    started = time.perf_counter()
    env = make_vec_env(args.env, n_envs=hp["n_envs"], seed=seed, env_kwargs=hp["env_kwargs"],
                       normalize=normalize_kwargs(hp), vectorization=args.vectorization)
    scorer = _Scorer(args.env, hp["env_kwargs"], args.eval_episodes, TUNE_EVAL_SEED)
    scores: list = []
    try:
        model = algo_class(args.algo)(hp["policy"], env, seed=seed, device="cpu", verbose=0,
                                      **algo_kwargs(hp))
        if hp.get("pretrain"):
            from .pretrain import pretrain

            pretrain(model, env, args.env, hp["env_kwargs"], hp["pretrain"],
                     gamma=float(hp.get("gamma", 0.99)))
        report = _trial_callback(trial, scorer, max(args.trial_timesteps // args.evaluations, 1),
                                 scores)
        callbacks = [report]
        if args.trial_minutes is not None:
            callbacks.append(TimeBudgetCallback(args.trial_minutes, started=started))
        try:
            model.learn(total_timesteps=args.trial_timesteps, callback=callbacks)
        except (ValueError, FloatingPointError, RuntimeError) as err:
            # a diverging draw (NaN in the network) is a failed trial, not a failed study
            trial.set_user_attr("error", f"{type(err).__name__}: {err}"[:300])
            raise optuna.TrialPruned() from None
        if not report.pruned and (not scores or scores[-1][0] != model.num_timesteps):
            scores.append((int(model.num_timesteps), scorer(model)))
    finally:
        env.close()
        scorer.close()
        trial.set_user_attr("scores", scores)
        trial.set_user_attr("steps", int(scores[-1][0]) if scores else 0)
        trial.set_user_attr("seconds", round(time.perf_counter() - started, 1))
    if report.pruned:
        raise optuna.TrialPruned()
    return scores[-1][1]


# -- the record ---------------------------------------------------------------------------------
def _jsonable(value):
    if isinstance(value, dict):
        return {str(k): _jsonable(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_jsonable(v) for v in value]
    if isinstance(value, (np.floating, np.integer)):
        return value.item()
    return value


def importances(study) -> dict[str, float]:
    """The parameters' importances for the trials' values (Optuna's
    PED-ANOVA over the complete trials: how much each parameter's
    distribution among the best trials differs from that among all);
    empty while fewer than two complete trials differ in value."""
    import optuna

    values = [t.value for t in study.trials if t.state == optuna.trial.TrialState.COMPLETE]
    if len(values) < 2 or np.ptp(values) == 0:
        return {}
    try:
        found = optuna.importance.get_param_importances(
            study, evaluator=optuna.importance.PedAnovaImportanceEvaluator())
    except (RuntimeError, ValueError, ImportError):
        return {}
    return {k: round(float(v), 4) for k, v in found.items()}


def study_record(study, args: argparse.Namespace, base_hp: dict, argv: list[str],
                 seconds: float) -> dict:
    """The study as a record: settings, every trial, the best trial and
    the importances."""
    import optuna

    from physics.provenance import source_commit

    from .reference import TUNE_EVAL_SEED, TUNE_TRAIN_SEED
    from .train import host_info

    trials = []
    for t in study.trials:
        trials.append(dict(number=t.number, state=t.state.name, value=t.value,
                           params=t.params, scores=t.user_attrs.get("scores", []),
                           steps=t.user_attrs.get("steps"), seconds=t.user_attrs.get("seconds"),
                           train_seed=t.user_attrs.get("train_seed"),
                           error=t.user_attrs.get("error")))
    complete = [t for t in study.trials if t.state == optuna.trial.TrialState.COMPLETE]
    best = None
    if complete:
        b = study.best_trial
        best = dict(number=b.number, value=b.value, params=b.params,
                    hyperparams=_jsonable(trial_hyperparams(base_hp, SAMPLERS[args.algo](
                        optuna.trial.FixedTrial(b.params)))))
    return _jsonable(dict(
        env=args.env, algo=args.algo, command=shlex.join(["python", "-m", "agents.tune", *argv]),
        commit=source_commit(), host=host_info(), date=time.strftime("%Y-%m-%d"),
        budget=dict(trials=args.trials, minutes=args.minutes,
                    trial_timesteps=args.trial_timesteps, trial_minutes=args.trial_minutes,
                    evaluations=args.evaluations, eval_episodes=args.eval_episodes),
        seeds=dict(train=f"{TUNE_TRAIN_SEED} + trial number",
                   episodes=f"{TUNE_EVAL_SEED} + k, k < {args.eval_episodes}",
                   sampler=args.seed + args.worker),
        sampler="TPE (multivariate)",
        pruner=f"median, after {STARTUP_TRIALS} complete trials and the first evaluation",
        wall_seconds=round(seconds, 1), base_hyperparams=base_hp,
        counts={s: sum(t["state"] == s for t in trials) for s in ("COMPLETE", "PRUNED", "FAIL")},
        best=best, importances=importances(study), trials=trials))


def _warm_start_words(hp: dict) -> str:
    settings = hp.get("pretrain")
    if not settings:
        return ""
    return (f" from a clone of the {settings['teacher']} ({settings['episodes']} episodes, "
            f"anchor {settings['anchor']:g})")


def markdown(record: dict) -> str:
    """``study.md``: the settings, the best trial, the importances and every trial."""
    c = record["counts"]
    lines = [f"## Hyperparameter study: {record['algo'].upper()} on `{record['env']}`", "",
             f"Made by `{record['command']}` at commit `{record['commit']}` on "
             f"{record['host']['cpu']} ({record['host']['logical_cpus']} logical CPUs), "
             f"{record['date']}, in {record['wall_seconds']:.0f} s.", "",
             f"{len(record['trials'])} trials: {c['COMPLETE']} complete, {c['PRUNED']} pruned, "
             f"{c['FAIL']} failed. A trial trains {record['budget']['trial_timesteps']} steps"
             f"{_warm_start_words(record['base_hyperparams'])} "
             f"and is scored {record['budget']['evaluations']} times on the same "
             f"{record['budget']['eval_episodes']} episodes (seeded "
             f"{record['seeds']['episodes']}); its value is its last score. Sampler: "
             f"{record['sampler']}; pruner: {record['pruner']}.", ""]
    best = record["best"]
    if best:
        lines += [f"Best trial: {best['number']}, value {best['value']:.4g}.", "",
                  "| parameter | best value | importance |", "|---|---|---|"]
        imp = record["importances"]
        for name in sorted(best["params"], key=lambda n: -imp.get(n, -1.0)):
            value = best["params"][name]
            shown = f"{value:.3g}" if isinstance(value, float) else str(value)
            lines.append(f"| {name} | {shown} | "
                         f"{imp[name]:.2f} |" if name in imp else f"| {name} | {shown} | |")
        lines.append("")
    lines += ["| trial | state | value | steps | seconds |", "|---|---|---|---|---|"]
    for t in record["trials"]:
        value = "" if t["value"] is None else f"{t['value']:.4g}"
        lines.append(f"| {t['number']} | {t['state'].lower()} | {value} | {t['steps'] or ''} | "
                     f"{t['seconds'] or ''} |")
    return "\n".join(lines) + "\n"


def plot(record: dict, path: Path) -> None:
    """``study.png``: every trial's scores against steps (pruned ones
    dashed) and the importances."""
    from physics.scenarios import plots

    plt = plots.pyplot()
    fig, (a, b) = plt.subplots(1, 2, figsize=(10, 4), gridspec_kw=dict(width_ratios=[3, 2]))
    best = (record["best"] or {}).get("number")
    for t in record["trials"]:
        if not t["scores"]:
            continue
        x, y = zip(*t["scores"])
        style = dict(lw=2.2, color="C3", zorder=3) if t["number"] == best else \
            dict(lw=0.9, color="C0" if t["state"] == "COMPLETE" else "0.6",
                 ls="-" if t["state"] == "COMPLETE" else "--")
        a.plot(x, y, marker="o", ms=2.5, **style)
    a.set(xlabel="environment steps of the trial", ylabel="score (mean return)",
          title=f"{len(record['trials'])} trials (best in red, pruned dashed)")
    imp = record["importances"]
    if imp:
        names = list(imp)[::-1]
        b.barh(names, [imp[n] for n in names], color="C0")
        b.set(xlabel="importance (PED-ANOVA)")
    else:
        b.text(0.5, 0.5, "importances need two\ncomplete trials that differ", ha="center",
               va="center", transform=b.transAxes)
        b.set_axis_off()
    fig.suptitle(f"{record['algo'].upper()} on {record['env']}")
    fig.tight_layout()
    fig.savefig(path, dpi=80)
    plt.close(fig)


def write_record(study, args, base_hp, argv, seconds) -> dict:
    """Write ``study.json``, ``study.md``, ``study.png`` and ``best.yaml``."""
    record = study_record(study, args, base_hp, argv, seconds)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "study.json").write_text(json.dumps(record, indent=1) + "\n")
    (out / "study.md").write_text(markdown(record))
    plot(record, out / "study.png")
    if record["best"]:
        entry = {k: v for k, v in record["best"]["hyperparams"].items() if k != "n_timesteps"}
        with open(out / "best.yaml", "w") as fh:
            fh.write(f"# the best trial ({record['best']['number']}, value "
                     f"{record['best']['value']:.4g}) of {record['command']}\n")
            yaml.safe_dump({record["env"]: entry}, fh, sort_keys=True)
    return record


def main(argv: list[str] | None = None, prog: str = "python -m agents.tune") -> dict:
    """Command-line entry point; returns the study's record."""
    import optuna

    from .envs import check_env_kwargs
    from .train import read_hyperparams

    argv = list(sys.argv[1:] if argv is None else argv)
    parser = build_parser(prog)
    args = parse_args(parser, argv)
    try:
        base_hp = read_hyperparams(args.algo, args.env, args.hyperparams, n_envs=args.n_envs,
                                   env_kwargs=args.env_kwargs)
        check_env_kwargs(args.env, base_hp["env_kwargs"], seed=0)
    except ValueError as err:
        parser.error(str(err))
    if args.warm_start and not base_hp.get("pretrain"):
        parser.error("--warm-start: the hyperparameters hold no pretrain entry (set one with "
                     "--hyperparams 'pretrain={teacher: heuristic}')")
    if not args.warm_start and base_hp.pop("pretrain", None):
        print("tuning without the warm start of the YAML (pretrain; --warm-start keeps it)",
              flush=True)
    optuna.logging.set_verbosity(optuna.logging.WARNING)
    storage = None
    if args.storage is not None:
        from optuna.storages import JournalStorage
        from optuna.storages.journal import JournalFileBackend

        args.storage.parent.mkdir(parents=True, exist_ok=True)
        storage = JournalStorage(JournalFileBackend(str(args.storage)))
    study = optuna.create_study(
        study_name=f"{args.env}:{args.algo}", storage=storage, load_if_exists=True,
        direction="maximize",
        sampler=optuna.samplers.TPESampler(seed=args.seed + args.worker, multivariate=True,
                                           n_startup_trials=min(5, args.trials)),
        pruner=optuna.pruners.MedianPruner(n_startup_trials=STARTUP_TRIALS, n_warmup_steps=1))
    started = time.perf_counter()

    def checkpoint(study, trial):
        write_record(study, args, base_hp, argv, time.perf_counter() - started)
        state = trial.state.name.lower()
        value = "" if trial.value is None else f", value {trial.value:.4g}"
        print(f"trial {trial.number}: {state}{value} after {trial.user_attrs.get('steps')} "
              f"steps, {trial.user_attrs.get('seconds')} s", flush=True)

    study.optimize(lambda trial: run_trial(trial, args, base_hp), n_trials=args.trials,
                   timeout=None if args.minutes is None else 60.0 * args.minutes,
                   callbacks=[checkpoint], show_progress_bar=not args.no_progress,
                   catch=())
    record = write_record(study, args, base_hp, argv, time.perf_counter() - started)
    best = record["best"]
    print(f"{len(record['trials'])} trials in {record['wall_seconds']:.0f} s; "
          + (f"best: trial {best['number']}, value {best['value']:.4g}" if best
             else "no trial completed") + f"; record in {args.out}", flush=True)
    return record


if __name__ == "__main__":
    main()
