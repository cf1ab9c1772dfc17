"""Reinforcement learning on the iceenvs environments (stable-baselines3).

Commands::

    python -m agents.train --env iceenvs/Convergence-v0 --algo ppo [--timesteps N]
        [--seed S] [--n-envs K] [--out DIR] [--force] [--eval-freq F]
        [--eval-episodes E] [--hyperparams key=value ...] [--env-kwargs key=value ...]
    python -m agents.evaluate RUN_DIR [--episodes 20] [--seed S]
        [--baselines random,zero,heuristic[,constant]] [--constant FILE.json] [--out DIR]
    python -m agents.evaluate --baseline NAME --env ID [--episodes N]
        [--env-kwargs key=value ...]
    python -m agents.constant --env ID [--grid 9] [--seeds 5] [--processes 2]
        [--env-kwargs key=value ...] [--out FILE.json]

Modules: :mod:`agents.train` (training runs), :mod:`agents.evaluate`
(policy against baselines), :mod:`agents.rollouts` (seeded episodes and
their statistics, shared by the commands), :mod:`agents.baselines`
(random, zero, constant and each environment's own controllers),
:mod:`agents.constant` (the best constant action of a grid search as a
baseline), :mod:`agents.callbacks` (physics
metrics, progress bar), :mod:`agents.envs` (vectorised environments,
``--env-kwargs`` parsing and checking),
:mod:`agents.metrics` (the physics entries each task logs, read from its
facts), :mod:`agents.pretrain` (a warm start of PPO from a planner's
decisions and an anchor to them in PPO's loss, the ``pretrain``
hyperparameter) and the hyperparameter tables
``agents/hyperparams/{ppo,sac}.yaml`` (a ``default`` entry, and an entry
per id only where the id needs one).

Importing the package imports neither torch nor stable-baselines3.
"""
