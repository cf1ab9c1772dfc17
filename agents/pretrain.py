"""Warm-start a policy from a planner's decisions (behaviour cloning).

A policy trained by PPO from scratch searches the whole action space; a
planner of the suite already knows a good route. The ``pretrain``
hyperparameter starts PPO from a copy of the planner instead:

1. **Demonstrations.** The planner (a baseline of
   :func:`agents.baselines.make_baseline`, e.g. ``swath``) sails
   ``episodes`` episodes of the training environment, seeded
   ``seed, seed + 1, …`` (apart from the fields of the leaderboard and of
   the training run), and each step's raw observation, action and reward
   are kept.
2. **Normalisation.** The observation statistics of ``VecNormalize`` are
   primed with the demonstrations' observations, and its return
   statistics with their discounted returns, so that the policy is fitted
   on the inputs it will see when PPO starts.
3. **Actor.** The mean of the policy's Gaussian is fitted to the planner's
   actions (mean squared error, Adam, ``epochs`` passes in batches of
   ``batch_size``). Its standard deviation stays at ``log_std_init``.
4. **Critic.** The value head is fitted to the discounted returns of the
   planner's episodes (normalised rewards, the run's ``gamma``), so that
   the first advantages of PPO are not those of a random critic.
5. **Anchor** (optional, ``anchor`` > 0). PPO may drift from the clone
   towards what pays under its exploration noise rather than on the mean
   course it is evaluated on. With an anchor, every optimiser step of PPO
   also descends ``anchor`` × the mean squared distance between the
   policy's mean action and the planner's on a batch of the
   demonstrations (:class:`BehaviourAnchor`): PPO's loss gains a
   behaviour-cloning term, as in demonstration-augmented policy gradients
   (Rajeswaran et al., 2018). The term's value is logged as
   ``train/anchor_mse``.

6. **DAgger** (optional, ``rounds`` > 0). After the clone, ``rounds``
   rounds of dataset aggregation (:mod:`agents.dagger`): the student
   drives ``episodes`` new episodes, the teacher's action played instead
   with probability ``beta``:sup:`r` in round r, the teacher labels every
   visited state, and the student is fitted again to all the labels so
   far. The anchor then holds PPO near the aggregated labels.

The hyperparameter is a mapping, e.g. in ``agents/hyperparams/ppo.yaml``::

    pretrain:
      teacher: swath
      episodes: 60
      seed: 30000
      epochs: 50
      anchor: 1.0

``pretrain.yaml`` in the run directory records the number of decisions,
the fit of actor and critic and the seconds each part took.

**Within a time budget.** Under ``agents.train --minutes M`` the warm start
belongs to the budget: it may take at most ``share`` (default 0.5) of it,
counted from the start of the run. The demonstrations stop when the next
episode would not end within 85 % of that share (at least one episode is
sailed), and the fit stops between epochs when the share is spent; PPO gets
the rest of the budget. A budget whose share cannot hold one episode of the
teacher is refused with the budget that would (:class:`BudgetTooShort`).
``pretrain.yaml`` then records how many of the ``episodes`` were sailed and
how many epochs were fitted.
"""
from __future__ import annotations

import time

import numpy as np

from . import observations as obs_rows

__all__ = ["PRETRAIN_DEFAULTS", "COLLECT_PART", "BudgetTooShort", "pretrain_settings",
           "Demonstrations", "collect", "prime_normalization", "fit_policy", "refit",
           "BehaviourAnchor", "pretrain"]

#: settings of ``pretrain`` that may be left out
PRETRAIN_DEFAULTS = {"episodes": 60, "seed": 30000, "epochs": 50, "batch_size": 256,
                     "learning_rate": 1.0e-3, "anchor": 0.0, "share": 0.5, "rounds": 0,
                     "beta": 0.5}
#: part of the warm start's share of a budget that the demonstrations may use
#: (the rest is the fit's)
COLLECT_PART = 0.85


class BudgetTooShort(ValueError):
    """A time budget whose share for the warm start cannot hold one episode
    of the teacher; the message names the budget that would."""


def pretrain_settings(value) -> dict | None:
    """The settings of a ``pretrain`` hyperparameter with defaults filled in
    (``None`` for none, ``False`` or an empty mapping).

    Raises
    ------
    ValueError
        For a value that is not a mapping, a mapping without ``teacher``,
        an unknown key or a count that is not a positive integer.
    """
    if value is None or value is False or value == {}:
        return None
    if not isinstance(value, dict):
        raise ValueError(f"hyperparameter pretrain must be a mapping with a teacher, got {value!r}")
    unknown = sorted(set(value) - {"teacher", *PRETRAIN_DEFAULTS})
    if unknown:
        raise ValueError(f"unknown pretrain settings {unknown}; valid: teacher, "
                         f"{', '.join(PRETRAIN_DEFAULTS)}")
    if not isinstance(value.get("teacher"), str):
        raise ValueError("hyperparameter pretrain needs a teacher: the name of a baseline such "
                         "as swath")
    settings = {**PRETRAIN_DEFAULTS, **value}
    for key in ("episodes", "epochs", "batch_size"):
        if not isinstance(settings[key], int) or isinstance(settings[key], bool) \
                or settings[key] < 1:
            raise ValueError(f"pretrain {key} must be an integer >= 1, got {settings[key]!r}")
    if not isinstance(settings["seed"], int) or isinstance(settings["seed"], bool):
        raise ValueError(f"pretrain seed must be an integer, got {settings['seed']!r}")
    if not float(settings["learning_rate"]) > 0:
        raise ValueError(f"pretrain learning_rate must be > 0, got {settings['learning_rate']!r}")
    if isinstance(settings["anchor"], bool) or not isinstance(settings["anchor"], (int, float)) \
            or not settings["anchor"] >= 0:
        raise ValueError(f"pretrain anchor must be a number >= 0, got {settings['anchor']!r}")
    settings["anchor"] = float(settings["anchor"])
    share = settings["share"]
    if isinstance(share, bool) or not isinstance(share, (int, float)) or not 0 < share < 1:
        raise ValueError(f"pretrain share (of a --minutes budget) must be a number in (0, 1), "
                         f"got {share!r}")
    settings["share"] = float(share)
    rounds = settings["rounds"]
    if isinstance(rounds, bool) or not isinstance(rounds, int) or rounds < 0:
        raise ValueError(f"pretrain rounds (of DAgger) must be an integer >= 0, got {rounds!r}")
    beta = settings["beta"]
    if isinstance(beta, bool) or not isinstance(beta, (int, float)) or not 0 <= beta <= 1:
        raise ValueError(f"pretrain beta must be a number in [0, 1], got {beta!r}")
    settings["beta"] = float(beta)
    return settings


class Demonstrations:
    """A teacher's decisions: raw observations ``obs`` (n, …; a dict of such
    arrays for a ``Dict`` observation), actions
    ``actions`` (n, k), rewards ``rewards`` (n,) and ``episode_starts``
    (n,), True at the first step of each episode; ``episodes`` is their
    number."""

    def __init__(self, obs, actions, rewards, episode_starts):
        self.obs = obs_rows.stack(list(obs)) if isinstance(obs, (list, tuple)) else \
            obs_rows.as_float32(obs)
        self.actions = np.asarray(actions, dtype=np.float32)
        self.rewards = np.asarray(rewards, dtype=np.float64)
        self.episode_starts = np.asarray(episode_starts, dtype=bool)

    def __len__(self) -> int:
        return obs_rows.length(self.obs)

    @property
    def episodes(self) -> int:
        return int(np.count_nonzero(self.episode_starts))

    def running_returns(self, gamma: float) -> np.ndarray:
        """The discounted return so far at each step, ``R_t = γ R_{t-1} +
        r_t`` (restarted at each episode): what ``VecNormalize`` tracks to
        scale the rewards."""
        out = np.empty(len(self))
        running = 0.0
        for t, (r, start) in enumerate(zip(self.rewards, self.episode_starts)):
            running = (0.0 if start else gamma * running) + r
            out[t] = running
        return out

    def returns_to_go(self, gamma: float, scale: float = 1.0) -> np.ndarray:
        """The discounted return from each step to the end of its episode,
        ``G_t = r_t / scale + γ G_{t+1}``: the value of the teacher."""
        out = np.empty(len(self))
        following = 0.0
        for t in range(len(self) - 1, -1, -1):
            ends = t == len(self) - 1 or self.episode_starts[t + 1]
            following = self.rewards[t] / scale + (0.0 if ends else gamma * following)
            out[t] = following
        return out


def collect(env_id: str, env_kwargs: dict, teacher: str, episodes: int, seed: int,
            progress: bool = False, deadline: float | None = None) -> Demonstrations:
    """Sail ``episodes`` episodes of ``teacher`` (a baseline name) on
    ``gymnasium.make(env_id, **env_kwargs)``, seeded ``seed + k``.

    With ``deadline`` (a ``time.perf_counter`` value), no episode is begun
    that would not end by then at the mean pace of those sailed so far;
    the first is always sailed, and :class:`BudgetTooShort` is raised when
    it ends past the deadline. ``Demonstrations.episodes`` says how many
    were sailed."""
    import gymnasium as gym
    from tqdm.auto import tqdm

    from .baselines import make_baseline

    env = gym.make(env_id, **env_kwargs)
    try:
        policy = make_baseline(teacher, env, seed=seed)
        obs_list, actions, rewards, starts = [], [], [], []
        began = time.perf_counter()
        with tqdm(range(episodes), desc=f"{teacher} demonstrations", unit="episode",
                  disable=not progress) as bar:
            for k in bar:                     # k episodes sailed so far
                if deadline is not None and k:
                    now = time.perf_counter()
                    if now + (now - began) / k > deadline:
                        break
                obs, _ = env.reset(seed=seed + k)
                policy.reset(seed + k)
                done, first = False, True
                while not done:
                    action = np.asarray(policy.predict(obs)[0], dtype=np.float32)
                    obs_list.append(obs_rows.as_float32(obs, copy=True))
                    actions.append(action.reshape(env.action_space.shape))
                    starts.append(first)
                    obs, reward, terminated, truncated, _ = env.step(action)
                    rewards.append(float(reward))
                    done, first = terminated or truncated, False
                if deadline is not None and k == 0 and time.perf_counter() > deadline:
                    took = time.perf_counter() - began
                    raise BudgetTooShort(f"one {teacher} episode took {took:.0f} s, more than "
                                         f"the warm start's share of the budget")
    finally:
        env.close()
    return Demonstrations(obs_list, actions, rewards, starts)


def prime_normalization(vec_normalize, demos: Demonstrations, gamma: float) -> None:
    """Start the statistics of a ``VecNormalize`` from the demonstrations:
    observations (when it normalises them) and discounted returns (when it
    normalises rewards)."""
    if vec_normalize.norm_obs and isinstance(vec_normalize.obs_rms, dict):
        for key in vec_normalize.norm_obs_keys:       # a Dict observation: its keys normalised
            vec_normalize.obs_rms[key].update(demos.obs[key])
    elif vec_normalize.norm_obs:
        vec_normalize.obs_rms.update(demos.obs)
    if vec_normalize.norm_reward:
        vec_normalize.ret_rms.update(demos.running_returns(gamma))


def _action_mse(policy, obs, actions):
    """The mean squared distance between the mean action of an SB3
    policy's distribution on ``obs`` and ``actions`` (torch tensors of
    the same leading length; a torch scalar)."""
    return ((policy.get_distribution(obs).distribution.mean - actions) ** 2).mean()


def _action_nll(policy, obs, actions):
    """The mean negative log-likelihood of the discrete ``actions`` under an
    SB3 policy's categorical distribution on ``obs`` (a torch scalar)."""
    return -policy.get_distribution(obs).log_prob(actions).mean()


def _fit(params, loss_of, n: int, epochs: int, batch_size: int, learning_rate: float,
         generator, deadline: float | None = None) -> int:
    """Adam on ``loss_of(batch_indices)`` over ``epochs`` passes of shuffled
    batches, or fewer when ``deadline`` (a ``time.perf_counter`` value)
    passes (at least one); returns the passes made."""
    import torch

    optimizer = torch.optim.Adam(params, lr=learning_rate)
    for done in range(epochs):
        if done and deadline is not None and time.perf_counter() > deadline:
            return done
        for batch in torch.randperm(n, generator=generator).split(batch_size):
            loss = loss_of(batch)
            optimizer.zero_grad()
            loss.backward()
            optimizer.step()
    return epochs


def fit_policy(policy, obs: np.ndarray, actions: np.ndarray, values: np.ndarray | None, *,
               epochs: int, batch_size: int, learning_rate: float, seed: int,
               deadline: float | None = None) -> dict:
    """Fit an SB3 actor-critic ``policy`` on (already normalised) ``obs``:
    the mean of its action distribution to ``actions`` and, when given,
    its value to ``values``.

    Only the actor's parameters (features, actor layers, action head)
    are trained for the actions, and only the critic's (value layers and
    head) for the values; the log standard deviation is left alone. With
    ``deadline`` (a ``time.perf_counter`` value) each fit stops between
    epochs when its part of the time left has passed (the actor's half,
    then the critic's).

    A policy of a ``Discrete`` action space is fitted by the likelihood of
    the teacher's actions (cross-entropy) instead of the squared distance.

    Returns
    -------
    dict
        ``action_mse``, ``action_variance`` (for a ``Discrete`` action space:
        ``action_nll`` and ``action_accuracy``, the share of ``actions`` that
        are the policy's most likely), ``actor_epochs`` and, with
        values, ``value_mse``, ``value_variance`` and ``critic_epochs``, on
        the whole data after the fit.
    """
    import torch

    generator = torch.Generator().manual_seed(int(seed))
    x = obs_rows.as_tensor(obs)
    n = obs_rows.length(x)
    from gymnasium.spaces import Discrete

    discrete = isinstance(policy.action_space, Discrete)
    loss = _action_nll if discrete else _action_mse
    y = (torch.as_tensor(actions, dtype=torch.long).reshape(n) if discrete else
         torch.as_tensor(actions, dtype=torch.float32).reshape(n, -1))
    policy.set_training_mode(True)

    actor = [*policy.pi_features_extractor.parameters(),
             *policy.mlp_extractor.policy_net.parameters(), *policy.action_net.parameters()]
    actor_deadline = None
    if deadline is not None:
        now = time.perf_counter()
        actor_deadline = now + 0.5 * (deadline - now) if values is not None else deadline
    def rows(b):
        return obs_rows.take(x, b)

    report = {"actor_epochs": _fit(actor, lambda b: loss(policy, rows(b), y[b]), n,
                                   epochs, batch_size, learning_rate, generator, actor_deadline)}
    with torch.no_grad():
        if discrete:
            report["action_nll"] = float(_action_nll(policy, x, y))
            best = policy.get_distribution(x).distribution.probs.argmax(dim=1)
            report["action_accuracy"] = float((best == y).float().mean())
        else:
            report["action_mse"] = float(_action_mse(policy, x, y))
            report["action_variance"] = float(y.var(unbiased=False))
    if values is not None:
        v = torch.as_tensor(values, dtype=torch.float32).reshape(-1, 1)
        critic = [*policy.mlp_extractor.value_net.parameters(), *policy.value_net.parameters()]
        if not policy.share_features_extractor:
            critic += list(policy.vf_features_extractor.parameters())
        report["critic_epochs"] = _fit(
            critic, lambda b: ((policy.predict_values(rows(b)) - v[b]) ** 2).mean(), n,
            epochs, batch_size, learning_rate, generator, deadline)
        with torch.no_grad():
            report["value_mse"] = float(((policy.predict_values(x) - v) ** 2).mean())
            report["value_variance"] = float(v.var(unbiased=False))
    policy.set_training_mode(False)
    return report


class BehaviourAnchor:
    """Add ``coef`` × the gradient of the behaviour-cloning loss to the
    gradients of ``model.policy`` before each step of its optimiser.

    The loss is the mean squared distance between the policy's mean
    action and the teacher's on ``batch_size`` demonstrations drawn
    (seeded by ``seed``) at each step; their raw observations are
    normalised with ``normalizer`` (a ``VecNormalize`` or ``None``) at
    its current statistics. The hook is registered on the optimiser, so
    it acts on every step of ``model.train()`` (after PPO has clipped its
    own gradient) and on nothing that is saved; :meth:`remove` takes it
    off.

    Attributes
    ----------
    mse : float
        The mean of the loss over the steps since the last rollout
        (``nan`` before the first), also recorded in the model's logger
        as ``train/anchor_mse``.
    """

    def __init__(self, model, demos: Demonstrations, normalizer, coef: float, batch_size: int,
                 seed: int):
        if not coef > 0:
            raise ValueError(f"anchor coefficient must be > 0, got {coef!r}")
        self.model, self.demos, self.normalizer = model, demos, normalizer
        self.coef, self.batch_size = float(coef), int(batch_size)
        self.rng = np.random.default_rng(seed)
        self.mse = float("nan")
        self._sum, self._count, self._timesteps = 0.0, 0, None
        self._handle = model.policy.optimizer.register_step_pre_hook(self._before_step)

    def loss(self):
        """The behaviour-cloning loss on a fresh batch (a torch scalar)."""
        import torch

        idx = self.rng.integers(len(self.demos), size=min(self.batch_size, len(self.demos)))
        obs = obs_rows.take(self.demos.obs, idx)
        if self.normalizer is not None:
            obs = self.normalizer.normalize_obs(obs)
        x = obs_rows.as_tensor(obs)
        y = torch.as_tensor(self.demos.actions[idx]).reshape(len(idx), -1)
        return _action_mse(self.model.policy, x, y)

    def _before_step(self, optimizer, args, kwargs) -> None:
        import torch

        with torch.enable_grad():
            loss = self.loss()
            (self.coef * loss).backward()
        if self._timesteps != self.model.num_timesteps:   # a new update
            self._sum, self._count, self._timesteps = 0.0, 0, self.model.num_timesteps
        self._sum += float(loss.detach())
        self._count += 1
        self.mse = self._sum / self._count
        self.model.logger.record("train/anchor_mse", self.mse)

    def remove(self) -> None:
        """Stop adding the term."""
        self._handle.remove()


def refit(policy, norm, demos: Demonstrations, added: Demonstrations, gamma: float,
          settings: dict, seed: int, deadline: float | None = None) -> dict:
    """Fit ``policy`` to the demonstrations ``demos`` (:func:`fit_policy`,
    with the ``epochs``, ``batch_size`` and ``learning_rate`` of
    ``settings``) on observations normalised by ``norm`` (a
    ``VecNormalize`` or None), after priming its statistics with the
    demonstrations ``added`` since the last fit; the values are the
    returns to go on the normalised reward scale."""
    obs, scale = demos.obs, 1.0
    if norm is not None:
        prime_normalization(norm, added, gamma)
        obs = norm.normalize_obs(demos.obs)
        if norm.norm_reward:
            scale = float(np.sqrt(norm.ret_rms.var + norm.epsilon))
    return fit_policy(policy, obs, demos.actions, demos.returns_to_go(gamma, scale),
                      epochs=settings["epochs"], batch_size=settings["batch_size"],
                      learning_rate=float(settings["learning_rate"]), seed=seed,
                      deadline=deadline)


def pretrain(model, env, env_id: str, env_kwargs: dict, settings: dict, gamma: float,
             progress: bool = False, deadline: float | None = None, rounds=None) -> dict:
    """Warm-start ``model`` (an SB3 actor-critic such as PPO) on the
    training stack ``env`` from the demonstrations of ``settings["teacher"]``
    (steps 1-5 of the module's description).

    With ``settings["rounds"]`` > 0, ``rounds`` (:func:`agents.dagger.dagger`,
    which this module does not import, since it builds on this one) runs the
    DAgger rounds after the clone. With ``settings["anchor"]`` > 0, a
    :class:`BehaviourAnchor` on the
    same demonstrations is left on the model's optimiser for PPO. With
    ``deadline`` (a ``time.perf_counter`` value: the end of the warm
    start's share of a budget) the demonstrations end by
    :data:`COLLECT_PART` of the time left and the fit by the deadline.

    Returns
    -------
    dict
        The settings, ``decisions``, ``episodes_sailed``, the fit
        (:func:`fit_policy`) and ``collect_seconds`` of the clone and
        ``fit_seconds`` (the DAgger rounds included); with DAgger rounds, ``dagger`` (a record per round,
        :func:`agents.dagger.dagger`) and ``aggregated_decisions``.
    """
    from stable_baselines3.common.vec_env import VecNormalize

    start = time.perf_counter()
    collect_by = None if deadline is None else start + COLLECT_PART * (deadline - start)
    demos = collect(env_id, env_kwargs, settings["teacher"], settings["episodes"],
                    settings["seed"], progress=progress, deadline=collect_by)
    collected = time.perf_counter()
    norm = env if isinstance(env, VecNormalize) else None
    report = refit(model.policy, norm, demos, demos, gamma, settings, settings["seed"],
                   deadline)
    clone = demos
    if settings["rounds"]:
        if rounds is None:
            raise ValueError("pretrain rounds > 0 need the DAgger rounds: pass "
                             "rounds=agents.dagger.dagger")
        demos, report["dagger"] = rounds(model, norm, env_id, env_kwargs, demos, settings,
                                         gamma, progress=progress, deadline=deadline)
        report["aggregated_decisions"] = len(demos)
    if settings["anchor"] > 0:
        BehaviourAnchor(model, demos, norm, settings["anchor"], settings["batch_size"],
                        seed=settings["seed"] + 1)
    return {**settings, "decisions": len(clone), "episodes_sailed": clone.episodes, **report,
            "collect_seconds": round(collected - start, 1),
            "fit_seconds": round(time.perf_counter() - collected, 1)}
