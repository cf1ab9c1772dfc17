"""Fine-tuning a waypoint student by reinforcement learning, at its own
pace: one action is one decision of :mod:`agents.waypoints`.

Imitation can at best sail as well as its teacher. To do better, the
student of :func:`agents.waypoints.train_student` is trained further by
PPO (Schulman et al. 2017) on the environment's own reward, in the terms
it decides in:

* **The environment** (:class:`WaypointDecisionEnv`): an action is a
  decision w (the waypoints' lateral shifts); the ship follows the route
  through them by pure pursuit for :data:`~agents.waypoints.DECISION_STEPS`
  steps (10 s, the lattice planner's replan), and the reward is the sum of
  the environment's rewards over those steps. The observation is
  :func:`agents.waypoints.decision_observation`: the costmap and the
  ship's pose, what the student saw while it imitated. Exploration noise
  is drawn once per decision, so it is held for 10 s: correlated in time
  at the pace the task is decided.
* **Starting from the student**: the policy's actor is the student's
  network, weights and all. The critic has a network of its own (its
  costmap CNN starts as a copy of the student's), so that fitting the
  value does not move the features the actor imitated with.
* **Keeping near the teacher at first**: the critic is fitted alone for
  ``critic_steps`` decisions (learning rate ``critic_learning_rate``),
  with the actor frozen; then both are trained with a smaller learning
  rate, a clip range of 0.1 and PPO's early stop on the approximate KL
  divergence. The exploration starts at the student's (a standard
  deviation of 0.1 on each shift). The rewards are divided by a running
  estimate of the discounted return's spread (SB3's ``VecNormalize``),
  so that the critic's targets are of order one.

* **A paired reward** (``paired_horizon`` H > 0, with ``gamma`` 0): the
  field's own difficulty dwarfs what one decision changes, so the
  environment's reward makes a noisy policy gradient. Instead each
  decision is scored against the costmap lattice on the same episode:
  from a snapshot, the decision's H-step return (the decision, then the
  costmap lattice) minus the costmap lattice's own; the field cancels.
  Each decision is then a problem of its own, whose best answer is one
  step of policy improvement over the costmap lattice (as the rollout
  planner takes at every replan; a learner that reached it would decide
  as that rollout does, from its sensors alone). Training is privileged
  (it steps copies of the episode); the student still decides from its
  costmap and pose.

* **A privileged critic** (``privileged_critic``): the critic also reads
  the lattice planner's price of the ice ahead (its expected reward to the
  goal line, from every floe within 500 m) and the field's concentration
  (:func:`privileged_observation`, :class:`agents.privileged.PrivilegedCriticPolicy`),
  so that its value follows the field as the returns do and the
  advantages carry less of the field's luck. The actor, the policy
  played, still reads the costmap and its pose alone.

* **A residual on the costmap lattice** (``residual``): the action is a
  correction δ to the costmap lattice's own decision w₀ at that moment,
  and the ship sails w₀ + δ (clipped); the policy starts as the student's
  network with its last layer set to zero, so that it starts as the
  costmap lattice exactly, not as the student that imitates it with an
  error. With the paired reward, a zero correction earns exactly nothing,
  and what is learned is where to leave the lattice's decision. Play it
  with :class:`agents.waypoints.WaypointResidual`.

The fields sailed are seeded ``field_seed`` + k, episode by episode, apart
from the leaderboard's and the tuning fields. Run::

    python -m agents.waypoints finetune --run runs/cm-fresh/seed_1 --seed 1 \\
        --out runs/cm-rl/seed_1

The output is a run directory like the student's (``student.zip``, the
student's network with the fine-tuned actor, so
:class:`agents.waypoints.WaypointStudent` plays it), with ``ppo.zip`` (the
whole PPO model) and ``finetune.json``: the settings, the reward, the mean
return of the training episodes in windows (the environment's, and with a
paired reward its sums too), the critic's explained variance update by
update (SB3's, of the returns of each rollout before the update), and the
wall time.
"""
from __future__ import annotations

import json
import time
from pathlib import Path

import gymnasium as gym
import numpy as np

from .waypoint_follower import (FINETUNE_RECORD, PRIVILEGED, RECORD, STUDENT, Commanded,
                                LatticeWaypoints, decision_observation, decision_space,
                                gather_records, rollout_decision, write_gathered)

__all__ = ["WaypointDecisionEnv", "finetune", "finetune_report", "FINETUNE_DEFAULTS",
           "FINETUNE_RECORD", "PPO_MODEL", "PRIVILEGED", "privileged_observation"]

#: the record of a fine-tuning run, and its whole PPO model (actor, critic and
#: optimiser, for ``PPO.load``), in its directory
PPO_MODEL = "ppo.zip"
#: what a record's ``reward`` says of a fine-tuning on the environment's own reward
ENV_REWARD = "the environment's"
#: the settings of :func:`finetune`
FINETUNE_DEFAULTS = dict(steps=20_000, critic_steps=4_096, n_steps=512, batch_size=128,
                         n_epochs=5, learning_rate=1e-4, critic_learning_rate=1e-3,
                         clip_range=0.1, target_kl=0.02, gamma=0.99, gae_lambda=0.95,
                         field_seed=80_000, paired_horizon=0, privileged_critic=False,
                         residual=False)


def privileged_observation(env, lattice) -> np.ndarray:
    """What a privileged critic sees beside the student's observation, two
    numbers of order one (float32):

    * the reward the lattice planner expects from the ship's pose to the
      goal line (:meth:`agents.planners.LatticePlanner.value_to_go`, which
      reads every floe within the lattice's 500 m), over the progress
      reward of the whole channel (``goal_distance`` / the step's length at
      full speed): the field ahead, priced;
    * the field's concentration (``field_concentration``).

    ``lattice``: a :class:`~agents.planners.LatticePlanner` on ``env``."""
    u = env.unwrapped
    whole = u.goal_distance / (u.max_speed * u.control_interval)
    return np.clip(np.array([lattice.value_to_go() / whole, u.field_concentration],
                            dtype=np.float32), -10.0, 10.0)


class WaypointDecisionEnv(gym.Env):
    """A ship environment seen at the decisions of a waypoint follower: an
    action is a decision w ∈ [−1, 1]^points, a step sails ``interval``
    environment steps (fewer when the episode ends) along its route, and
    the reward is their rewards' sum.

    ``info`` of a step holds ``env_steps`` (the environment steps it sailed),
    ``env_reward`` (their rewards' sum), with ``paired_horizon`` the two
    rollouts' returns (``decision_return``, ``lattice_return``), and the
    last environment step's info.

    Parameters
    ----------
    env : gymnasium.Env
        A ship environment (e.g. ``gymnasium.make("iceenvs/ShipNavigation-v1")``);
        closed with this one.
    field_seed : int or None
        A reset without a seed seeds episode k of this environment's life
        ``field_seed`` + k (None: the environment's own sequence).
    paired_horizon : int
        0 (default): the reward is the environment's. H > 0: the reward is
        the decision's advantage over the costmap lattice, paired on the
        same episode (privileged: it steps copies of the episode). From a
        snapshot (:meth:`iceenvs.base.ControlEnv.snapshot`) the costmap
        lattice (:class:`agents.planners.CostmapLatticePlanner`) sails H
        steps; from the same snapshot the decision is sailed for
        ``interval`` steps and the costmap lattice sails on to H; the
        reward is the second sum minus the first. Field, ice and weather
        are the same in both, so what the field gives every policy cancels,
        and what is left is what the decision changed (for the lattice's
        own decision, exactly zero). The episode then goes on from the
        decision's own ``interval`` steps. Each decision costs 2 H + ``interval``
        steps.
    privileged : bool
        Add :func:`privileged_observation` to the observation under
        :data:`PRIVILEGED`, for a privileged critic (:mod:`agents.privileged`);
        the student's own observation is unchanged beside it.
    residual : bool
        An action is a correction δ to the costmap lattice's decision w₀
        (:class:`agents.waypoints.LatticeWaypoints` with teacher
        ``"costmap-lattice"``, clipped to [−1, 1]) at the step's start: the
        ship sails w₀ + δ, clipped (``info["base"]``: w₀). δ = 0 sails the
        costmap lattice's episode.
    **follower : :class:`agents.waypoints.WaypointFollower`'s settings
        (``points``, ``distance``, ``interval``, ``max_slope``, ...; form
        ``"waypoints"`` only).

    """

    metadata = {"render_modes": []}

    def __init__(self, env, field_seed: int | None = None, paired_horizon: int = 0,
                 privileged: bool = False, residual: bool = False, **follower):
        if follower.get("form", "waypoints") != "waypoints":
            raise ValueError("WaypointDecisionEnv decides lateral shifts (form 'waypoints'), "
                             f"got form {follower['form']!r}")
        self.env = env
        self.follower = Commanded(env, **follower)
        if isinstance(paired_horizon, bool) or int(paired_horizon) != paired_horizon or not (
                paired_horizon == 0 or paired_horizon >= self.follower.interval):
            raise ValueError(f"paired_horizon must be 0 (off) or an integer of at least the "
                             f"decision's {self.follower.interval} steps, got {paired_horizon!r}")
        if paired_horizon and not hasattr(env.unwrapped, "snapshot"):
            raise ValueError(f"paired_horizon needs an environment with snapshot and restore, "
                             f"got {type(env.unwrapped).__name__}")
        self.paired_horizon = int(paired_horizon)
        if not isinstance(privileged, (bool, np.bool_)):
            raise TypeError(f"privileged must be True or False, got {privileged!r}")
        self.observation_space = decision_space(env)
        self._lattice = None
        if privileged:
            from .planners import LatticePlanner

            self._lattice = LatticePlanner(env, 0, show=False)
            self._lattice.require_value_to_go("privileged")
            self.observation_space = gym.spaces.Dict({
                **self.observation_space.spaces,
                PRIVILEGED: gym.spaces.Box(-10.0, 10.0, (2,), np.float32)})
        if not isinstance(residual, (bool, np.bool_)):
            raise TypeError(f"residual must be True or False, got {residual!r}")
        self._base = None
        if residual:
            self._base = LatticeWaypoints(
                env, 0, teacher="costmap-lattice", points=self.follower.points,
                distance=self.follower.distance, interval=self.follower.interval)
        self.action_space = gym.spaces.Box(-1.0, 1.0, (self.follower.points,), np.float32)
        self.field_seed = field_seed
        self._episodes = 0
        self._obs = None

    def reset(self, *, seed: int | None = None, options=None):
        super().reset(seed=seed)
        if seed is None and self.field_seed is not None:
            seed = self.field_seed + self._episodes
        self._episodes += 1
        self._obs, info = self.env.reset(seed=seed, options=options)
        self.follower.reset(seed)
        return self._observation(), info

    def _observation(self) -> dict:
        obs = decision_observation(self.env)
        if self._lattice is not None:
            obs[PRIVILEGED] = privileged_observation(self.env, self._lattice)
        return obs

    def step(self, action):
        if self._obs is None:
            raise RuntimeError("WaypointDecisionEnv.step before reset")
        w = np.asarray(action, dtype=float).reshape(-1)
        if w.shape != self.action_space.shape or not np.all(np.isfinite(w)):
            raise ValueError(f"a decision is {self.action_space.shape[0]} finite number(s) "
                             f"in [-1, 1], got {action!r}")
        paired = {}
        if self._base is not None:
            paired["base"] = np.clip(self._base.label(), -1.0, 1.0)
            w = np.clip(paired["base"] + w, -1.0, 1.0)
        if self.paired_horizon:
            u = self.env.unwrapped
            snap = u.snapshot()
            # restore before each rollout: a restore puts copies in the episode, so the
            # rollouts step those and leave alone the objects this environment holds
            u.restore(snap)
            paired["lattice_return"] = self._rollout(None)
            u.restore(snap)
            paired["decision_return"] = self._rollout(w)
            u.restore(snap)
        self.follower.command = w
        self.follower.decide_next_step()
        total, steps = 0.0, 0
        terminated = truncated = False
        info: dict = {}
        while steps < self.follower.interval and not (terminated or truncated):
            self._obs, reward, terminated, truncated, info = self.env.step(
                self.follower.predict(self._obs)[0])
            total += float(reward)
            steps += 1
        reward = paired["decision_return"] - paired["lattice_return"] \
            if self.paired_horizon else total
        return (self._observation(), reward, terminated, truncated,
                {**info, "env_steps": steps, "env_reward": total, **paired})

    def _rollout(self, w) -> float:
        """The summed reward of ``paired_horizon`` steps of the episode as it
        is now (the caller restores it): decision ``w`` for ``interval``
        steps, then the costmap lattice; None: the costmap lattice
        throughout (:func:`agents.waypoint_follower.rollout_decision`)."""
        f = self.follower
        return rollout_decision(self.env, self._obs, w, self.paired_horizon, points=f.points,
                                distance=f.distance, interval=f.interval)

    def close(self):
        self.env.close()


class _EnvReturns(gym.Wrapper):
    """Keeps each episode's sum of the environment's own rewards
    (``info["env_reward"]``), whatever reward the learner is given."""

    def __init__(self, env):
        super().__init__(env)
        self.returns: list[float] = []
        self._sum = 0.0

    def reset(self, **kwargs):
        self._sum = 0.0
        return self.env.reset(**kwargs)

    def step(self, action):
        obs, reward, terminated, truncated, info = self.env.step(action)
        self._sum += float(info["env_reward"])
        if terminated or truncated:
            self.returns.append(self._sum)
        return obs, reward, terminated, truncated, info


def _actor_parameters(policy):
    return [*policy.pi_features_extractor.parameters(),
            *policy.mlp_extractor.policy_net.parameters(),
            *policy.action_net.parameters(), policy.log_std]


def _from_student(policy, student) -> None:
    """Load the student's weights into ``policy`` (a PPO policy of the same
    network but a critic CNN of its own, which starts as the student's; a
    privileged critic's map of its privileged signals starts at zero)."""
    import torch

    source = student.state_dict()
    target = policy.state_dict()
    loaded = {}
    for key in target:
        if key.startswith("vf_features_extractor.inject."):
            loaded[key] = torch.zeros_like(target[key])
            continue
        origin = ("features_extractor." + key.split(".", 1)[1]
                  if key.startswith(("pi_features_extractor.", "vf_features_extractor."))
                  else key)
        origin = origin.replace("features_extractor.base.", "features_extractor.", 1)
        if origin not in source or source[origin].shape != target[key].shape:
            raise ValueError(f"the student has no weights for {key!r} of this network")
        loaded[key] = source[origin]
    with torch.no_grad():
        policy.load_state_dict(loaded)


def _to_student(policy, student):
    """``student`` (the student's own network, one costmap CNN shared by its
    actor and critic) with the actor of the fine-tuned ``policy``: what
    :class:`agents.waypoints.WaypointStudent` plays. (SB3 saves a policy
    without its ``share_features_extractor``, so a policy of two CNNs is
    loaded back as one, and with the critic's.)"""
    import torch

    tuned = policy.state_dict()
    mine = student.state_dict()
    for key in mine:
        if key.startswith(("features_extractor.", "pi_features_extractor.",
                           "vf_features_extractor.")):
            mine[key] = tuned["pi_features_extractor." + key.split(".", 1)[1]]
        elif key.startswith(("mlp_extractor.policy_net.", "action_net.", "log_std")):
            mine[key] = tuned[key]
    with torch.no_grad():
        student.load_state_dict(mine)
    return student


def finetune(run: str | Path, out: str | Path, seed: int, progress: bool = True,
             command: str | None = None, **settings) -> dict:
    """Fine-tune the student of ``run`` (a directory of
    :func:`agents.waypoints.train_student`) by PPO on
    :class:`WaypointDecisionEnv` of its training's environment, and save
    the policy as ``out/student.zip`` with the record ``out/finetune.json``.

    ``settings``: :data:`FINETUNE_DEFAULTS` (``steps`` and
    ``critic_steps``: decisions in all and of the critic's fit alone).
    """
    import torch
    from stable_baselines3 import PPO
    from stable_baselines3.common.monitor import Monitor
    from stable_baselines3.common.policies import MultiInputActorCriticPolicy
    from stable_baselines3.common.utils import set_random_seed
    from stable_baselines3.common.vec_env import DummyVecEnv, VecNormalize

    import iceenvs  # noqa: F401  (registers the ids)

    from .callbacks import TqdmCallback, UpdateLog

    unknown = sorted(set(settings) - set(FINETUNE_DEFAULTS))
    if unknown:
        raise ValueError(f"unknown settings {unknown}; valid: {', '.join(FINETUNE_DEFAULTS)}")
    s = {**FINETUNE_DEFAULTS, **settings}
    for name in ("steps", "n_steps", "batch_size", "n_epochs"):
        if isinstance(s[name], bool) or int(s[name]) != s[name] or s[name] < 1:
            raise ValueError(f"{name} must be an integer >= 1, got {s[name]!r}")
    if isinstance(s["critic_steps"], bool) or int(s["critic_steps"]) != s["critic_steps"] \
            or not 0 <= s["critic_steps"] < s["steps"]:
        raise ValueError(f"critic_steps must be an integer in [0, steps), got "
                         f"{s['critic_steps']!r}")
    run, out = Path(run), Path(out)
    for name in (STUDENT, RECORD):
        if not (run / name).is_file():
            raise FileNotFoundError(f"{run} is not a run of python -m agents.waypoints train: "
                                    f"{run / name} is missing")
    trained = json.loads((run / RECORD).read_text())["settings"]
    student = MultiInputActorCriticPolicy.load(str(run / STUDENT), device="cpu")
    if isinstance(student.action_space, gym.spaces.Discrete):
        raise ValueError(f"{run} decides stage choices; fine-tuning takes a student of "
                         f"form 'waypoints'")
    if s["paired_horizon"] and s["gamma"] != 0.0:
        raise ValueError(f"with paired_horizon the reward of a decision is its advantage over "
                         f"the costmap lattice over the horizon: each decision is its own "
                         f"problem, so gamma must be 0 (got {s['gamma']})")
    made = gym.make(trained["env_id"], **trained["env_kwargs"])
    if not isinstance(s["privileged_critic"], (bool, np.bool_)):
        made.close()
        raise ValueError(f"privileged_critic must be True or False, got "
                         f"{s['privileged_critic']!r}")
    if not isinstance(s["residual"], (bool, np.bool_)):
        made.close()
        raise ValueError(f"residual must be True or False, got {s['residual']!r}")
    env = WaypointDecisionEnv(made, field_seed=s["field_seed"],
                              paired_horizon=s["paired_horizon"],
                              privileged=s["privileged_critic"], residual=s["residual"],
                              points=int(student.action_space.shape[0]))
    if env.observation_space["costmap"].shape != student.observation_space["costmap"].shape:
        env.close()
        raise ValueError(f"the student of {run} was trained on other costmaps than its "
                         f"environment makes now")
    policy_kwargs = {k: getattr(student, k) for k in (
        "net_arch", "activation_fn", "ortho_init", "log_std_init", "features_extractor_class",
        "features_extractor_kwargs", "normalize_images")}
    policy_kwargs["share_features_extractor"] = False
    out.mkdir(parents=True, exist_ok=True)
    own = _EnvReturns(env)
    monitored = Monitor(own)
    # the rewards scaled by a running estimate of the return's spread (the
    # environment's own are kept in the record)
    vec = VecNormalize(DummyVecEnv([lambda: monitored]), norm_obs=False, norm_reward=True,
                       gamma=s["gamma"])
    # torch and numpy seeded here, not by PPO's ``seed``, which would also
    # seed the first field (it is field_seed)
    set_random_seed(seed)
    # the learning rate of each phase, read by PPO at every update
    rate = {"now": s["critic_learning_rate"]}
    policy_class = "MultiInputPolicy"
    if s["privileged_critic"]:
        from .privileged import PrivilegedCriticPolicy as policy_class
    model = PPO(policy_class, vec, learning_rate=lambda _: rate["now"],
                n_steps=s["n_steps"], batch_size=s["batch_size"], n_epochs=s["n_epochs"],
                gamma=s["gamma"], gae_lambda=s["gae_lambda"], clip_range=s["clip_range"],
                target_kl=s["target_kl"], policy_kwargs=policy_kwargs,
                device="cpu", verbose=0)
    _from_student(model.policy, student)
    if s["residual"]:
        # the correction starts at zero: the policy starts as the costmap lattice
        with torch.no_grad():
            model.policy.action_net.weight.zero_()
            model.policy.action_net.bias.zero_()
    began = time.perf_counter()
    actor = _actor_parameters(model.policy)
    # the critic's explained variance, update by update
    updates = UpdateLog(("train/explained_variance",))
    if s["critic_steps"]:
        for p in actor:
            p.requires_grad_(False)
        model.learn(s["critic_steps"], reset_num_timesteps=True,
                    callback=[TqdmCallback(s["critic_steps"], disable=not progress), updates])
        for p in actor:
            p.requires_grad_(True)
    rate["now"] = s["learning_rate"]
    rest = s["steps"] - s["critic_steps"]
    model.learn(rest, reset_num_timesteps=not s["critic_steps"],
                callback=[TqdmCallback(rest, disable=not progress), updates])
    returns = [float(r) for r in monitored.get_episode_rewards()]
    lengths = [int(n) for n in monitored.get_episode_lengths()]
    window = 10

    def by_window(values):
        return [round(float(np.mean(values[i:i + window])), 3)
                for i in range(0, len(values), window)]

    record = {"settings": {**s, "seed": seed, "run": str(run), "env_id": trained["env_id"],
                           "env_kwargs": trained["env_kwargs"]},
              "reward": (f"paired: advantage over the costmap lattice in {s['paired_horizon']} "
                         f"steps" if s["paired_horizon"] else ENV_REWARD)
              + ("; the action a correction to the costmap lattice's decision"
                 if s["residual"] else ""),
              "episodes": len(returns),
              "mean_return_by_window": by_window(returns),
              "mean_env_return_by_window": by_window(own.returns[:len(returns)]),
              "window": window,
              "decisions": int(sum(lengths)),
              "critic_episodes": _episodes_within(lengths, s["critic_steps"]),
              "explained_variance": [round(v, 4) if np.isfinite(v) else None
                                     for v in updates.values["train/explained_variance"]],
              "seconds": round(time.perf_counter() - began, 1),
              "torch_threads": torch.get_num_threads(),
              "command": command}
    _to_student(model.policy, student).save(str(out / STUDENT))
    model.save(str(out / PPO_MODEL))
    (out / FINETUNE_RECORD).write_text(json.dumps(record, indent=2) + "\n")
    vec.close()
    return record


def _episodes_within(lengths, decisions: int) -> int:
    """How many whole episodes of ``lengths`` (decisions each) end within
    the first ``decisions``."""
    return int(np.searchsorted(np.cumsum(lengths), decisions, side="right"))


def _env_windows(record: dict) -> list:
    """A fine-tuning's mean return (the environment's reward) by window of
    episodes; a record before paired rewards has only its own sums, which
    are the same."""
    return record.get("mean_env_return_by_window", record["mean_return_by_window"])


def _explained(record: dict, n: int = 3) -> str:
    """The mean explained variance of a fine-tuning's first and last ``n``
    updates ("–" for a record without them)."""
    values = [v for v in record.get("explained_variance", []) if v is not None]
    if not values:
        return "–"
    return f"{np.mean(values[:n]):.2f} → {np.mean(values[-n:]):.2f}"


def finetune_report(runs, out: str | Path) -> dict:
    """Gather the records of the fine-tuning runs ``runs`` (directories of
    :func:`finetune`) into ``out``: ``finetune.json`` (each run's record, by
    its directory as given), ``finetune.md`` (a table of the runs) and
    ``finetune.png`` (each run's mean return of the training episodes, by
    windows of 10 episodes)."""
    from physics.scenarios import plots

    records = gather_records(runs, FINETUNE_RECORD, "agents.waypoints finetune")
    lines = ["| run | seed | from the student | reward | decisions (critic alone) | episodes "
             "| mean reward sum, first and last 10 episodes | mean return (the environment's "
             "reward), the same | critic's explained variance, first and last 3 updates "
             "| training [min] |", "|---|---|---|---|---|---|---|---|---|---|"]
    for name, record in records.items():
        s, windows = record["settings"], record["mean_return_by_window"]
        env_windows = _env_windows(record)
        lines.append(f"| {name} | {s['seed']} | {s['run']} | "
                     f"{record.get('reward', ENV_REWARD)} | "
                     f"{record['decisions']} ({s['critic_steps']}) | {record['episodes']} "
                     f"| {windows[0]:.1f} → {windows[-1]:.1f} "
                     f"| {env_windows[0]:.1f} → {env_windows[-1]:.1f} "
                     f"| {_explained(record)} "
                     f"| {record['seconds'] / 60:.1f} |")
    first = next(iter(records.values()))["settings"]
    lines += ["", f"Fields: seeded {first['field_seed']} + k, one per episode; learning rate "
              f"{first['critic_learning_rate']:g} for the critic alone, then {first['learning_rate']:g}; "
              f"{first['n_steps']} decisions a rollout, {first['n_epochs']} epochs of "
              f"{first['batch_size']}, clip {first['clip_range']:g}, target KL "
              f"{first['target_kl']:g}. The explained variance is SB3's, of each "
              f"rollout's returns by the critic's values before the update (1: the critic "
              f"foresees them; 0: no better than their mean). The training episodes' returns are of the "
              f"stochastic policy, on fields of every concentration: the leaderboard judges.",
              ""]
    out = write_gathered(out, FINETUNE_RECORD, records, "finetune.md", lines)
    plt = plots.pyplot()
    explained = any(record.get("explained_variance") for record in records.values())
    fig, axes = plt.subplots(1, 2 if explained else 1, figsize=(12 if explained else 7, 4.2),
                             squeeze=False)
    ax = axes[0, 0]
    for name, record in records.items():
        windows = _env_windows(record)
        x = record["window"] * (np.arange(len(windows)) + 1)
        ax.plot(x, windows, lw=1.2, label=name)
        ax.axvline(record["critic_episodes"], color="0.6", lw=0.8, ls=":")
    ax.set_title("runs with the same field_seed sail the same fields in turn: "
                 "their common swings are the fields'", fontsize=9)
    ax.set_xlabel("training episodes (dotted: the critic's fit alone ends)")
    ax.set_ylabel(f"mean return of {next(iter(records.values()))['window']} episodes")
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    if explained:
        ax = axes[0, 1]
        for name, record in records.items():
            values = [np.nan if v is None else v for v in record.get("explained_variance", [])]
            ax.plot(np.arange(1, len(values) + 1), values, lw=1.2, marker=".", label=name)
            ax.axvline(record["settings"]["critic_steps"] / record["settings"]["n_steps"] + 0.5,
                       color="0.6", lw=0.8, ls=":")
        ax.set_title("the critic's explained variance of each rollout's returns, before "
                     "its update", fontsize=9)
        ax.set_xlabel("update (dotted: the critic's fit alone ends)")
        ax.set_ylabel("explained variance")
        ax.legend(fontsize=8)
        ax.grid(alpha=0.3)
    plots.savefig(fig, out / "finetune.png", dpi=110, palette=True)
    return records
