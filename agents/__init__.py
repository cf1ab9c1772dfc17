"""Reinforcement learning on the iceenvs environments (stable-baselines3).

Commands::

    python -m agents.train --env iceenvs/Convergence-v0 --algo ppo [--timesteps N]
        [--seed S] [--n-envs K] [--out DIR] [--force] [--eval-freq F]
        [--eval-episodes E] [--hyperparams key=value ...]
    python -m agents.evaluate RUN_DIR [--episodes 20] [--seed S]
        [--baselines random,zero,heuristic] [--out DIR]
    python -m agents.evaluate --baseline NAME --env ID [--episodes N]

Modules: :mod:`agents.train` (training runs), :mod:`agents.evaluate`
(policy against baselines), :mod:`agents.baselines` (random, zero and
hand-written controllers), :mod:`agents.callbacks` (physics metrics,
progress bar), :mod:`agents.envs` (vectorised environments),
:mod:`agents.metrics` (which physics entries each task logs) and the
hyperparameter tables ``agents/hyperparams/{ppo,sac}.yaml``.

Importing the package imports neither torch nor stable-baselines3.
"""
