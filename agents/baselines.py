"""Baseline policies with the ``predict`` interface of SB3 models.

``predict(obs, deterministic=True) -> (action, None)`` accepts one
observation or a batch. Every baseline reads the *raw* observation of the
environment (not a normalised one) and may keep state within an episode;
``reset(seed)`` starts a new episode.

================  ==========================================================
name              policy
================  ==========================================================
``random``        uniform samples of the action space, seeded
``zero``          the all-zero action, clipped into the space
``constant``      one fixed action (``action=``; :mod:`agents.constant` finds the best)
``heuristic``     the hand-written controller of the environment (below)
``straight``      ship environments: full speed straight to the goal line
``reactive``      ship environments: steer for the least obstructed lidar sector
================  ==========================================================

>>> env = gymnasium.make("iceenvs/Convergence-v0")
>>> policy = make_baseline("heuristic", env)
>>> obs, _ = env.reset(seed=0)
>>> action, _ = policy.predict(obs)
"""
from __future__ import annotations

import math

import gymnasium as gym
import numpy as np

from iceenvs.observations import log_stress

__all__ = ["Baseline", "RandomPolicy", "ZeroPolicy", "ConstantPolicy", "WindDriftController",
           "ConvergenceController", "MarginalIceZoneController", "FloeClusteringController",
           "ThicknessDistributionController", "StraightLinePolicy", "ReactivePlanner",
           "HEURISTICS", "BASELINES", "make_baseline"]


class Baseline:
    """Base of the baselines: batching, clipping and episode resets.

    Parameters
    ----------
    env : gymnasium.Env
        The environment the policy acts in (spaces, feature layout and
        task parameters are read from it).
    seed : int
        Seed of any random choice of the policy.
    """

    def __init__(self, env: gym.Env, seed: int = 0):
        self.env = env
        self.action_space = env.action_space
        self.observation_space = env.observation_space
        self.seed = int(seed)

    def reset(self, seed: int | None = None) -> None:
        """Start a new episode (``seed``: the episode's seed)."""

    def act(self, obs: np.ndarray) -> np.ndarray:
        """The action for one raw observation."""
        raise NotImplementedError

    def predict(self, obs, state=None, episode_start=None, deterministic: bool = True):
        """``(action, None)`` for one observation or a batch (first axis)."""
        obs = np.asarray(obs, dtype=np.float32)
        low, high = self.action_space.low, self.action_space.high
        if obs.ndim == len(self.observation_space.shape) + 1:
            actions = np.stack([np.clip(self.act(o), low, high) for o in obs])
            return actions.astype(self.action_space.dtype), None
        return np.clip(self.act(obs), low, high).astype(self.action_space.dtype), None


class RandomPolicy(Baseline):
    """Uniform random actions from a copy of the action space seeded with
    ``seed`` (re-seeded with each episode's seed by ``reset``)."""

    def __init__(self, env, seed: int = 0):
        super().__init__(env, seed)
        s = self.action_space
        self._space = gym.spaces.Box(s.low, s.high, s.shape, s.dtype, seed=self.seed)

    def reset(self, seed: int | None = None) -> None:
        if seed is not None:
            self._space.seed(int(seed))

    def act(self, obs):
        return self._space.sample()


class ZeroPolicy(Baseline):
    """The all-zero action clipped into the action space: no wind, no
    convergence, the kernel's own redistribution rate."""

    def act(self, obs):
        return np.zeros(self.action_space.shape)


def _check_action(space, action) -> np.ndarray:
    """``action`` as an array of the space's shape, finite and inside the
    bounds (a relative tolerance of 1e-6 of the box width for rounding)."""
    try:
        a = np.array(action, dtype=np.float64)
    except (TypeError, ValueError) as err:
        raise ValueError(f"a constant action must be an array of numbers, got {action!r}: "
                         f"{err}") from None
    shape = tuple(space.shape)
    if a.shape != shape:
        raise ValueError(f"a constant action must have the action space's shape {shape}, got "
                         f"{a.shape} ({action!r})")
    if not np.all(np.isfinite(a)):
        raise ValueError(f"a constant action must be finite, got {action!r}")
    low = np.asarray(space.low, dtype=np.float64)
    high = np.asarray(space.high, dtype=np.float64)
    width = np.where(np.isfinite(high - low), high - low, 1.0)
    tol = 1e-6 * np.maximum(width, 1.0)
    if np.any(a < low - tol) or np.any(a > high + tol):
        raise ValueError(f"constant action {a.tolist()} is outside the action space "
                         f"[{low.tolist()}, {high.tolist()}]")
    return np.clip(a, low, high)


class ConstantPolicy(Baseline):
    """The same action at every step.

    Parameters
    ----------
    env : gymnasium.Env
        The environment (its action space must be a ``Box``).
    seed : int
        Unused (the policy is deterministic); kept for the baseline
        interface ``(env, seed)``.
    action : array-like, optional
        The action, of the action space's shape and inside its bounds.
        Default: the centre of the box, (low + high) / 2.

    Raises
    ------
    ValueError
        For an action of the wrong shape, not finite or out of bounds, or
        no action with an unbounded box.
    """

    def __init__(self, env, seed: int = 0, *, action=None):
        super().__init__(env, seed)
        space = self.action_space
        if action is None:
            low = np.asarray(space.low, dtype=np.float64)
            high = np.asarray(space.high, dtype=np.float64)
            if not (np.all(np.isfinite(low)) and np.all(np.isfinite(high))):
                raise ValueError("an unbounded action space has no centre; pass action=")
            action = 0.5 * (low + high)
        self.action = _check_action(space, action).astype(space.dtype)

    @classmethod
    def best(cls, env, results, seed: int = 0) -> "ConstantPolicy":
        """The policy of the best action of a search: ``results`` is the list
        of :func:`search_constant_actions`, or the path of the JSON file of
        ``python -m agents.constant``."""
        from .constant import best_action

        return cls(env, seed, action=best_action(results))

    def act(self, obs):
        return self.action.copy()

    def __repr__(self) -> str:
        return f"ConstantPolicy(action={self.action.tolist()})"


class _FloeController(Baseline):
    """A controller of a floe environment: observation entries by feature
    name."""

    def __init__(self, env, seed: int = 0):
        super().__init__(env, seed)
        names = [f.name for f in env.unwrapped.features]
        self._index = {n: k for k, n in enumerate(names)}
        self.reward_params = env.unwrapped.reward_params

    def _get(self, obs, name: str) -> float:
        return float(obs[self._index[name]])


class WindDriftController(_FloeController):
    """Blow along the target heading, corrected for the turning of the drift.

    The wind points along the heading (read from the observation), turned
    to the left by an angle ``turn`` and scaled so that its largest
    component is 1 (the strongest wind the action box allows in that
    direction; the drift speed grows with the wind, the action cost of
    0.01 |a|² is small against it). Coriolis turns the drift to the right
    of the wind, so ``turn`` is adapted from the measured drift: each step
    it changes by ``-gain`` × the angle of the mean ice velocity from the
    heading (once the ice moves faster than 1 cm/s), within ±45°. When the
    pressure passes the task's ``pressure_max`` the wind is halved, because
    the reward penalises the excess.
    """

    gain = 0.3
    max_turn = math.pi / 4
    turn = 0.0         # the current turn of the wind from the heading

    def reset(self, seed=None):
        self.turn = 0.0

    def act(self, obs):
        hx, hy = self._get(obs, "heading_cos"), self._get(obs, "heading_sin")
        ux, uy = self._get(obs, "u_x"), self._get(obs, "u_y")
        if math.hypot(ux, uy) > 0.01:
            error = math.atan2(hx * uy - hy * ux, hx * ux + hy * uy)   # drift left of heading > 0
            self.turn = float(np.clip(self.turn - self.gain * error, -self.max_turn,
                                      self.max_turn))
        heading = math.atan2(hy, hx) + self.turn
        wind = np.array([math.cos(heading), math.sin(heading)])
        wind /= np.max(np.abs(wind))
        if self._get(obs, "pressure") > log_stress(self.reward_params["pressure_max"]):
            wind *= 0.5
        return wind


class ConvergenceController(_FloeController):
    """Proportional control of the concentration with a pressure limit.

    The convergence rate is ``-gain`` × the observed error (A − A*)/0.1,
    clipped to the action bounds: full convergence far below the target,
    slowing down within 0.1/gain of it, divergence above it. As the ice
    approaches jamming the pressure rises steeply; between half of the
    task's ``pressure_max`` and ``pressure_max`` the convergence rate is
    scaled down linearly in log pressure to 0, and above ``pressure_max``
    the box diverges slowly (−0.2) to relieve the pressure.
    """

    gain = 20.0

    def act(self, obs):
        rate = float(np.clip(-self.gain * self._get(obs, "error"), -1.0, 1.0))
        p = self._get(obs, "pressure")
        p_max = log_stress(self.reward_params["pressure_max"])
        p_soft = log_stress(0.5 * self.reward_params["pressure_max"])
        if p > p_max:
            rate = -0.2
        elif p > p_soft and rate > 0:
            rate *= (p_max - p) / (p_max - p_soft)
        return np.array([rate])


class MarginalIceZoneController(_FloeController):
    """Feed-forward and integral control of the wind speed towards the
    target transport, with the wind turned away from the fast ice as the
    edge stress rises.

    The transport grows with the wind speed: 20 m/s of wind along the edge
    gives about 0.1 m/s. The speed command (action[0]) therefore starts at
    the wind that would give the target on that estimate, −1 + 2 u* /
    0.1 m/s, and is then integrated from the observed transport error:
    each step it changes by ``gain`` × (u* − u_x) / 0.05 m/s, within
    [−1, 1]. With Coriolis the drift turns to the right of the wind,
    i.e. towards the fast-ice edge for wind along +x; as the edge stress
    rises from a quarter of the task's ``edge_stress_max`` to
    ``edge_stress_max`` (in log stress) the wind is turned left, away from
    the edge, by up to ``extra`` × π (36°), so that the ice is not pressed
    onto the edge.
    """

    base = 0.0
    extra = 0.2
    gain = 0.4
    _speed = None      # the current speed command (None: not yet set this episode)

    def reset(self, seed=None):
        self._speed = None

    def act(self, obs):
        target = self._get(obs, "target_speed")
        if self._speed is None:
            self._speed = float(np.clip(-1.0 + 2.0 * target / 0.1, -1.0, 1.0))
        error = (target - self._get(obs, "u_x")) / 0.05
        self._speed = float(np.clip(self._speed + self.gain * error, -1.0, 1.0))
        s = self._get(obs, "edge_stress")
        s_max = log_stress(self.reward_params["edge_stress_max"])
        s_low = log_stress(0.25 * self.reward_params["edge_stress_max"])
        load = float(np.clip((s - s_low) / (s_max - s_low), 0.0, 1.0))
        return np.array([self._speed, self.base + self.extra * load])


class FloeClusteringController(_FloeController):
    """Steady wind to build clusters, alternating wind to break them.

    Below the target largest-cluster fraction the wind blows steadily
    along +x with a strength proportional to the deficit (full at a
    deficit of 0.2, at least 0.2): under Stokes drag floes of different
    sizes drift at different speeds, collide and gather. Above the target
    the wind reverses direction every step with a strength proportional to
    the excess, which shears the clusters apart; within ±0.02 of the
    target the wind is off.
    """

    _sign = 1.0        # direction of the last alternating wind

    def reset(self, seed=None):
        self._sign = 1.0

    def act(self, obs):
        error = self._get(obs, "target") - self._get(obs, "largest_cluster")
        if error > 0.02:
            return np.array([float(np.clip(error / 0.2, 0.2, 1.0)), 0.0])
        if error < -0.02:
            self._sign = -self._sign
            return np.array([self._sign * float(np.clip(-error / 0.2, 0.2, 1.0)), 0.0])
        return np.zeros(2)


class ThicknessDistributionController(Baseline):
    """Receding-horizon choice of the kernel scale: the redistribution
    strength that keeps g(h) closest to the target over the next
    ``horizon`` steps.

    Every ``replan`` steps, each redistribution action in ``levels``
    (kernel scale 10**a: 0.1× … 10×) is tried on a copy of the
    environment's thickness model, held for ``horizon`` steps of the
    environment's ``days_per_step``, and the one with the smallest sum of
    the Wasserstein-1 distances to the target along the way (the negative
    of the rewards it would earn) is taken and held until the next
    choice (ties: the first, i.e. the weakest). The sum, not the distance
    at the end of the horizon, is what matters: the seasonal cycle moves
    g(h) away from the target whatever the action, and a greedy end-point
    rule does no better than the zero action. This is a model-based
    controller: it reads the model state and the target from the
    environment (``env.unwrapped``), not only the observation, which is
    why it is a yardstick a learned policy must approach from
    observations alone. Rafting consumes ice thinner than 0.5 m, so it is
    full (+1) when the observed fraction of ice below 0.5 m exceeds the
    target's and off (−1) otherwise.
    """

    levels = (-1.0, -0.5, 0.0, 0.5, 1.0)
    horizon = 60
    replan = 10
    _step = 0          # steps of the episode so far
    _choice = 0.0      # the redistribution action held until the next plan

    def reset(self, seed=None):
        self._step = 0
        self._choice = 0.0

    def _cost(self, model, target, h, redistribution: float, rafting: float) -> float:
        import copy

        from iceenvs.rewards import wasserstein1
        from iceenvs.thickness_distribution import RAFT_CUTOFF, RAFT_MAX

        env = self.env.unwrapped
        trial = copy.deepcopy(model)
        trial.kernel_scale = 10.0 ** redistribution
        factor = 1.0 + (RAFT_MAX - 1.0) * (rafting + 1.0) * 0.5
        if factor != trial.rafting_factor:
            trial.set_rafting(factor, RAFT_CUTOFF)
        total = 0.0
        for _ in range(self.horizon):
            trial.step(env.days_per_step)
            total += wasserstein1(trial.g, target, h)
        return total

    def act(self, obs):
        env = self.env.unwrapped
        target = env.target
        rafting = 1.0 if float(obs[1]) > float(env.coarse(target)[1]) else -1.0
        step = self._step
        self._step = step + 1
        if env.model is None:
            return np.array([0.0, rafting])
        if step % self.replan == 0:
            cost = [self._cost(env.model, target, env.h, a, rafting) for a in self.levels]
            self._choice = self.levels[int(np.argmin(cost))]
        return np.array([self._choice, rafting])


class StraightLinePolicy(Baseline):
    """A ship sailing straight for the goal line at full speed.

    The heading error is the bearing of the goal direction in the ship
    frame, atan2(``goal_sin``, ``goal_cos``). A prescribed ship turns at a
    yaw rate proportional to it (full rate at 0.1 rad); a dynamic ship
    runs at full thrust with a critically damped PD autopilot on it
    (natural frequency 0.05 rad/s, the ship's yaw inertia with added mass).
    The surge speed of ``control="speed_yaw"`` is the largest.

    The policies read the observation vector (``obs["vector"]`` of a dict
    observation); with ``obs_type="image"`` they read the environment's last
    physical observation instead, one environment at a time.
    """

    #: heading error [rad] of a full yaw-rate command
    GAIN_ANGLE = 0.1
    #: natural frequency [rad/s] of the dynamic ship's heading autopilot
    FREQUENCY = 0.05

    def __init__(self, env, seed: int = 0):
        super().__init__(env, seed)
        u = env.unwrapped
        if not hasattr(u, "lidar_sectors"):
            raise ValueError(f"{type(self).__name__} steers a ship environment, got "
                             f"{type(u).__name__}")
        self.unwrapped = u
        self._index = {f.name: k for k, f in enumerate(u.features)}
        self._scale = {f.name: (100.0 if f.scaling == "/ 100 m" else
                                0.1 if f.scaling == "/ 0.1 rad/s" else 1.0)
                       for f in u.features}

    def _reader(self, obs):
        """``get(name)``: the raw value of an observation entry."""
        if isinstance(obs, dict):
            obs = obs["vector"]
        if self.unwrapped.obs_type == "image":
            now = self.unwrapped._prev
            return lambda name: float(now[name])
        return lambda name: float(obs[self._index[name]]) * self._scale[name]

    def _bearing(self, get) -> float:
        """Bearing of the goal [rad, ship frame, port positive]."""
        return math.atan2(get("goal_sin"), get("goal_cos"))

    def _steer(self, bearing: float, get) -> np.ndarray:
        u = self.unwrapped
        if u.control == "thrust":
            ship = u._ship                # the episode's ship (set by reset)
            w = self.FREQUENCY
            moment = ship.total_mass[2] * (w * w * bearing - 2.0 * w * get("yaw_rate"))
            return np.array([1.0, moment / ship.max_yaw_moment])
        turn = bearing / self.GAIN_ANGLE
        return np.array([turn]) if u.control == "yaw" else np.array([1.0, turn])

    def act(self, obs):
        get = self._reader(obs)
        return self._steer(self._bearing(get), get)

    def predict(self, obs, state=None, episode_start=None, deterministic: bool = True):
        space = self.action_space
        vector = obs["vector"] if isinstance(obs, dict) else obs
        if self.unwrapped.obs_type != "image" and np.ndim(vector) == 2:
            if isinstance(obs, dict):
                rows = [{"vector": v} for v in vector]
            else:
                rows = list(vector)
            actions = np.stack([np.clip(self.act(o), space.low, space.high) for o in rows])
            return actions.astype(space.dtype), None
        return np.clip(self.act(obs), space.low, space.high).astype(space.dtype), None


class ReactivePlanner(StraightLinePolicy):
    """Steer for the least obstructed sector of the ice lidar.

    Each sector k of the lidar (central bearing θ_k) scores
    d_k / range − c_k − ``turn_cost`` |θ_k − θ_goal|, with d_k the distance
    to the first floe edge, c_k the ice concentration of the sector and
    θ_goal the bearing of the goal; the ship steers for the best sector
    (bearings beyond 60° of the goal are clipped there) as
    :class:`StraightLinePolicy` steers for the goal.
    """

    turn_cost = 0.5
    max_off_goal = math.radians(60.0)

    def act(self, obs):
        u = self.unwrapped
        get = self._reader(obs)
        k = u.lidar_sectors
        theta = -0.5 * math.pi + (np.arange(k) + 0.5) * math.pi / k
        d = np.array([get(f"lidar_distance_{i}") for i in range(k)]) / u.lidar_range
        c = np.array([get(f"lidar_concentration_{i}") for i in range(k)])
        goal = self._bearing(get)
        score = d - c - self.turn_cost * np.abs(theta - goal)
        best = float(theta[int(np.argmax(score))])
        return self._steer(float(np.clip(best, goal - self.max_off_goal,
                                         goal + self.max_off_goal)), get)


#: env name → its hand-written controller
HEURISTICS = {
    "WindDrift-v0": WindDriftController,
    "Convergence-v0": ConvergenceController,
    "MarginalIceZone-v0": MarginalIceZoneController,
    "FloeClustering-v0": FloeClusteringController,
    "ThicknessDistribution-v0": ThicknessDistributionController,
    "ShipNavigation-v0": ReactivePlanner,
    "ShipBeset-v0": ReactivePlanner,
}


def _heuristic(env, seed: int = 0) -> Baseline:
    name = env.spec.id.split("/")[-1] if env.spec is not None else ""
    if name not in HEURISTICS:
        raise ValueError(f"no heuristic controller for {name or type(env).__name__}; "
                         f"controllers exist for {', '.join(HEURISTICS)}")
    return HEURISTICS[name](env, seed)


#: baseline name → constructor ``(env, seed)``
BASELINES = {"random": RandomPolicy, "zero": ZeroPolicy, "heuristic": _heuristic,
             "constant": ConstantPolicy, "straight": StraightLinePolicy,
             "reactive": ReactivePlanner}


def make_baseline(name: str, env: gym.Env, seed: int = 0, **kwargs) -> Baseline:
    """The baseline ``name`` (a key of :data:`BASELINES`) for ``env``;
    ``kwargs`` go to its constructor (``action=`` for ``"constant"``).

    Raises
    ------
    ValueError
        For an unknown name (the message lists the valid ones).
    """
    if name not in BASELINES:
        raise ValueError(f"unknown baseline {name!r}; valid baselines: "
                         f"{', '.join(BASELINES)}")
    return BASELINES[name](env, seed, **kwargs)
