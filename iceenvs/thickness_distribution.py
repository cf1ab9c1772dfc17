"""``iceenvs/ThicknessDistribution-v0``: hold the ice thickness distribution
at a target through the seasonal cycle."""
from __future__ import annotations

import copy
import math

import gymnasium as gym
import numpy as np

from physics.input_checks import check_range
from physics.itd import YEAR_DAYS, ThorndikeModel, make_kernel
from physics.params import GODLOVITCH

from .base import ControlEnv, TaskParameter
from .step import Episodes
from .controllers import Controller
from .facts import EnvFacts
from .vector import vector_class
from .rewards import (closeness, cumulative_fractions, thickness_distribution_reward,
                      wasserstein1, wasserstein1_to)

__all__ = ["ThicknessDistributionEnv", "ThicknessDistributionVectorEnv",
           "ThicknessDistributionController", "default_target",
           "RAFT_MAX", "RAFT_CUTOFF", "COARSE_WIDTH", "N_COARSE", "MEAN_SCALE"]

RAFT_MAX = 2.0 * GODLOVITCH.raft_factor   # rafting factor at action[1] = +1 (1 at −1)
RAFT_CUTOFF = 0.5                # m: rafting acts where both floes are thinner than this
COARSE_WIDTH = 0.5               # m: width of the coarse observation classes
N_COARSE = 20                    # coarse ice classes; the last gathers h >= 9.5 m
MEAN_SCALE = 10.0                # m: the mean thickness is observed in these units
TARGET_OPEN_WATER = 0.05         # open-water fraction of the default target
TARGET_EFOLDING = 1.0            # m: λ of the default target g ∝ h exp(−h/λ)
START_NOISE = 0.1                # log-normal perturbation of the default start
# default kernel parameters: the calibrated rates (r0 for the constant kernel)
DEFAULT_KERNEL_PARAMS = GODLOVITCH.kernels

MAX_EPISODE_STEPS = 360         # one year of daily steps


def _as_given(name, value):
    """Distributions are checked against the env's classes in ``_check_episode_task``."""
    return value


_TASK = (
    TaskParameter("target", None, "target g(h) on the fine classes (n_classes + 1 entries, "
                  "open water first; normalised here); None: the default target", _as_given),
    TaskParameter("g0", None, "start g(h), same form as `target`; None: the target with "
                  "every ice class multiplied by exp(0.1 ξ), ξ standard normal, renormalised",
                  _as_given),
)


def default_target(h, open_water: float = TARGET_OPEN_WATER,
                   efolding: float = TARGET_EFOLDING) -> np.ndarray:
    """The default target on the class thicknesses ``h`` (open water first):
    ``open_water`` of open water and the rest ice with g ∝ h exp(−h/λ),
    λ = ``efolding`` [m] (mean ice thickness 2λ), normalised to sum 1."""
    h = np.asarray(h, dtype=float)
    ice = h[1:] * np.exp(-h[1:] / efolding)
    g = np.empty(h.size)
    g[0] = open_water
    g[1:] = (1.0 - open_water) * ice / ice.sum()
    return g


def _coarse_index(h) -> np.ndarray:
    """Coarse class of every fine class: 0 for open water, 1 + j for ice with
    j·0.5 m <= h < (j + 1)·0.5 m, j < 19, and 20 for h >= 9.5 m."""
    h = np.asarray(h, dtype=float)
    j = np.floor(h[1:] / COARSE_WIDTH + 1e-9).astype(np.intp)
    idx = np.empty(h.size, dtype=np.intp)
    idx[0] = 0
    idx[1:] = 1 + np.minimum(j, N_COARSE - 1)
    return idx


def _distribution(name: str, value, size: int) -> np.ndarray:
    """A fine-class distribution from ``reset`` options: 1-D of ``size``
    entries, finite, >= 0 and not all 0; returned normalised to sum 1."""
    try:
        g = np.array(value, dtype=float)
    except (TypeError, ValueError) as err:
        raise ValueError(f"{name} must be an array of {size} fractions: {err}") from None
    if g.shape != (size,):
        raise ValueError(f"{name} must have shape ({size},) (open water first, then the "
                         f"n_classes ice classes), got {g.shape}")
    if not np.all(np.isfinite(g)) or np.any(g < 0):
        raise ValueError(f"{name} must be finite and >= 0")
    total = g.sum()
    if not total > 0:
        raise ValueError(f"{name} must have a positive sum")
    return g / total


_TABLE_ROWS = "\n".join(
    f"    | {1 + j} | `g_{1 + j}` | ice of {j * COARSE_WIDTH:g} m <= h < "
    f"{(j + 1) * COARSE_WIDTH:g} m | area fraction | [0, 1] |"
    for j in range(N_COARSE - 1))


class ThicknessDistributionController(Controller):
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


class ThicknessDistributionEnv(ControlEnv):
    __doc__ = f"""Keep the sea-ice thickness distribution g(h) close to a target
    through the seasonal cycle by controlling mechanical redistribution.

    ## Description
    The generalised Thorndike model of Godlovitch et al. (the ice thickness
    distribution as a coagulation process, after Thorndike 2000), in
    :class:`physics.itd.ThorndikeModel`: area fractions g_0 (open water) and
    g_1 … g_n of ice of thickness kΔh ({GODLOVITCH.n_classes} classes of
    {GODLOVITCH.class_width:g} m by default).
    Mechanical redistribution stacks two floes of thicknesses h1 and h2 into
    one of h1 + h2 and frees one cell of open water (a Smoluchowski
    coagulation kernel K(h1, h2)); thermodynamics grows thin ice in winter
    and melts ice in summer over a 360-day year that starts in mid-winter
    (day 0). The agent sets the strength of the redistribution and of rafting
    (thin ice over-riding thin ice) every `days_per_step` model days. Stronger
    stacking builds thick ice and opens water, weaker stacking lets
    thermodynamics thin the pack; the seasonal cycle keeps pushing g(h)
    away from any fixed target.

    The default kernel is the constant kernel K = r0 with the rate
    r0 = {GODLOVITCH.r0:g}/day of Godlovitch's Fig. 4 as calibrated in the
    :data:`physics.params.GODLOVITCH` preset (`r_constant`); the other named
    kernels ("exponential", "multiplicative", "additive") default to their
    calibrated rates there (:meth:`~physics.params.ItdPreset.kernel_params`). One step costs about the time of
    `days_per_step` model days of the Thorndike model (a few forward-Euler
    substeps of O(n²) each).

    ## Action Space
    `Box(-1, 1, (2,), float32)`; NaN/inf entries are set to 0 and entries
    clipped into [-1, 1]:

    | Index | Action | Mapping |
    |---|---|---|
    | 0 | redistribution intensity | kernel scale = 10**action[0]: 0.1× … 10× the kernel's rate (1× at 0) |
    | 1 | rafting strength | rafting factor = 1 + (RAFT_MAX − 1)(action[1] + 1)/2, RAFT_MAX = 2 × {GODLOVITCH.raft_factor:g} = {RAFT_MAX:g}: 1 (no rafting) … {RAFT_MAX:g}, the kernel multiplied by it where both floes are thinner than {RAFT_CUTOFF:g} m |

    ## Observation Space
    `Box(float32)` of {N_COARSE + 6} entries, every entry clipped into its
    bounds. The fine classes are summed into open water and {N_COARSE} coarse
    classes of {COARSE_WIDTH:g} m (a fine class of thickness h = kΔh goes to
    the coarse class whose interval holds h; the last gathers everything
    thicker):

    | Index | Name | Meaning | Unit | Bounds |
    |---|---|---|---|---|
    | 0 | `g_0` | open water | area fraction | [0, 1] |
{_TABLE_ROWS}
    | {N_COARSE} | `g_{N_COARSE}` | ice of h >= {(N_COARSE - 1) * COARSE_WIDTH:g} m | area fraction | [0, 1] |
    | {N_COARSE + 1} | `season_cos` | cos(2π t / 360 d) of the model day t (1 mid-winter) | - | [-1, 1] |
    | {N_COARSE + 2} | `season_sin` | sin(2π t / 360 d) | - | [-1, 1] |
    | {N_COARSE + 3} | `mean_thickness` | mean thickness over the whole area (open water 0) / {MEAN_SCALE:g} m | - | [0, 2] |
    | {N_COARSE + 4}, {N_COARSE + 5} | `action` | the last action | - | [-1, 1] |

    `info["physics"]` holds the raw values: `g` (fine fractions, a copy),
    `h` (fine class thicknesses [m], open water 0 first), `open_water`,
    `mean_thickness` [m], `day` (model time [days]), `kernel_scale`,
    `rafting_factor` and `w1` (the Wasserstein-1 distance to the target
    [m]); `info["target"]` is the target on the fine classes.

    ## Rewards
    :func:`iceenvs.rewards.thickness_distribution_reward`: built on the
    Wasserstein-1 distance W1 [m] between the fine g(h) and the target,
    ∫ |G(h) − G*(h)| dh with G the cumulative fractions (0 when g equals the
    target). `reward_fn=` replaces it; it is called as
    `reward_fn(prev, action, now, distance_scale=..., target=..., h=...)` with
    the physics dicts.
    The reward in [0, 1] is 1 − W1 / `distance_scale` (default 1 m, a
    `reward_params` entry), at least 0. A physics failure ends the episode
    with reward 0.

    ## Starting State
    Day 0 (mid-winter). The default target is an exponential-tailed
    distribution like the Beaufort Sea mean: open water
    {TARGET_OPEN_WATER:g} and ice with g ∝ h exp(−h/λ), λ = {TARGET_EFOLDING:g} m (mean
    ice thickness about 2 m), normalised. The start is the target with every
    ice class multiplied by exp({START_NOISE:g} ξ), ξ standard normal from the
    env's seeded generator, and renormalised.

    ## Task parameters
    Keywords of `gymnasium.make` (kept for every episode) and entries of
    `reset(options=...)` (this episode only); unknown names raise an error
    that lists the valid ones:

    | name | default | meaning |
    |---|---|---|
    | `target` | None | target g(h) on the fine classes (n_classes + 1 entries, open water first, finite, >= 0; normalised here); None: the default target |
    | `g0` | None | start g(h), same form as `target`; None: the target perturbed as above |

    ## Task analysis
    * *Reachable:* the start is the target perturbed by 10 % per class.
    * *Best constant action:* the seasonal cycle of growth and melt pushes
      g(h) away from the target in opposite directions in winter and
      summer, so a fixed redistribution rate cannot hold it all year. The
      best of a grid of constant actions is measured in the docs' training
      page.
    * *What a good policy does:* strengthens the redistribution when
      thermodynamics thins the pack and weakens it when the pack thickens.

    ## Episode End
    Truncated after `max_episode_steps` (registered: {MAX_EPISODE_STEPS}
    steps, one year of 360 days with `days_per_step=1`). Terminated only
    when the physics fails (`info["error"]`).

    ## Arguments
    `kernel="constant"` (a kernel name of :func:`physics.itd.make_kernel`
    other than "rafting", which the action controls; a callable K(x, y) of
    thicknesses [m]; or an n × n matrix), `kernel_params=None` (e.g.
    `dict(r=...)`, replacing the defaults; default: the calibrated rates of
    the named kernels),
    `n_classes={GODLOVITCH.n_classes}`, `dh={GODLOVITCH.class_width:g}` [m] (the fine classes),
    `days_per_step={GODLOVITCH.time_step:g}`,
    `reward_fn=None`, `reward_params=None` (`distance_scale`),
    `render_mode=None` ("rgb_array" or "human"), and the task parameters.

    ## Version History
    * v0: rewards in [0, 1], task parameters as `gymnasium.make` keywords,
      episode length by `max_episode_steps`.
    """  # noqa: E501  (Markdown table rows cannot wrap)

    action_space = gym.spaces.Box(-1.0, 1.0, (2,), dtype=np.float32)
    action_names = ("redistribution", "rafting")
    reward_fn = staticmethod(thickness_distribution_reward)
    facts = EnvFacts(
        summary="steer the ice thickness distribution",
        metrics={"w1": "wasserstein1", "open_water": "open_water",
                 "mean_thickness": "mean_thickness", "kernel_scale": "kernel_scale",
                 "rafting_factor": "rafting_factor"},
        main_metric="wasserstein1",
        controllers={"heuristic": ThicknessDistributionController},
        small={"n_classes": 60},
        speed_target=5000)
    task_parameters = _TASK

    episode_members = ("model",)
    #: the observation's work buffer, written whole before it is read
    episode_caches = ("_vec", "_target_of", "_target_cumulative")

    def __init__(self, *, kernel="constant", kernel_params: dict | None = None,
                 n_classes: int = GODLOVITCH.n_classes, dh: float = GODLOVITCH.class_width,
                 days_per_step: float = GODLOVITCH.time_step,
                 reward_fn=None, reward_params: dict | None = None,
                 render_mode: str | None = None, **task):
        if isinstance(n_classes, bool) or not isinstance(n_classes, (int, np.integer)) \
                or n_classes < 2:
            raise ValueError(f"n_classes must be an integer >= 2, got {n_classes!r}")
        check_range("dh", dh, 0.0, None, low_open=True)
        check_range("days_per_step", days_per_step, 0.0, None, low_open=True)
        self._set_render_mode(render_mode)
        if kernel_params is not None and not isinstance(kernel_params, dict):
            raise ValueError(f"kernel_params must be a dict, got {type(kernel_params).__name__}")
        if isinstance(kernel, str) and kernel == "rafting":
            raise ValueError('kernel="rafting" is not available: the action sets the rafting '
                             'of any kernel')
        if kernel_params is None:
            kernel_params = (dict(DEFAULT_KERNEL_PARAMS.get(kernel, {}))
                             if isinstance(kernel, str) else {})
        elif kernel_params and not isinstance(kernel, str):
            raise ValueError("kernel_params apply to named kernels only, not to a callable "
                             "or a matrix")
        if reward_fn is not None and not callable(reward_fn):
            raise ValueError("reward_fn must be callable as reward(prev, action, now, **params)")

        self.n_classes = int(n_classes)
        self.dh = float(dh)
        self.days_per_step = float(days_per_step)
        self.kernel = kernel
        self.kernel_params = dict(kernel_params)
        try:
            # a private copy: a matrix passed in is not shared with the caller
            self._K = np.array(make_kernel(kernel, self.n_classes, self.dh,
                                           **self.kernel_params))
        except TypeError as err:
            raise ValueError(f"bad kernel or kernel_params: {err}") from None
        self.reward_fn = reward_fn if reward_fn is not None else type(self).reward_fn
        self._default_reward = reward_fn is None
        self._init_reward_params({"distance_scale": 1.0}, reward_params,
                                 custom=reward_fn is not None)
        if self._default_reward:
            check_range("distance_scale", self.reward_params["distance_scale"], 0.0, None,
                        low_open=True)

        h = np.concatenate([[0.0], self.dh * np.arange(1, self.n_classes + 1)])
        h.setflags(write=False)
        self._h = h
        self._dh = np.diff(h)                           # class widths [m]
        self._target_of = self._target_cumulative = None
        self._coarse_idx = _coarse_index(h)
        self._h_coarse = np.concatenate(
            [[0.0], COARSE_WIDTH * (np.arange(N_COARSE) + 0.5)])      # class centres [m]
        self._default_target = default_target(h)
        self._default_target.setflags(write=False)
        self._init_task(task)

        n_obs = N_COARSE + 6
        low = np.zeros(n_obs, dtype=np.float32)
        high = np.ones(n_obs, dtype=np.float32)
        low[N_COARSE + 1:N_COARSE + 3] = -1.0
        high[N_COARSE + 3] = 2.0
        low[N_COARSE + 4:] = -1.0
        self.observation_space = gym.spaces.Box(low, high, dtype=np.float32)
        self._low64 = low.astype(np.float64)
        self._high64 = high.astype(np.float64)
        self._vec = np.zeros(n_obs)                     # work buffer of the observation

        self.model: ThorndikeModel | None = None
        Episodes([self], single=True)

    # -- helpers ----------------------------------------------------------------------
    @property
    def target(self) -> np.ndarray:
        """The target distribution on the fine classes (open water first): the
        episode's, or before the first episode the one it will have by
        default."""
        target = self.episode["target"]
        return self._default_target if target is None else target

    @property
    def h(self) -> np.ndarray:
        """Fine class thicknesses [m], open water (0) first."""
        return self._h

    def coarse(self, g) -> np.ndarray:
        """Fine fractions summed into open water and the coarse classes."""
        return np.bincount(self._coarse_idx, weights=g, minlength=N_COARSE + 1)

    def apply_action(self, a: np.ndarray) -> None:
        m = self.model
        m.kernel_scale = 10.0 ** float(a[0])
        factor = 1.0 + (RAFT_MAX - 1.0) * (float(a[1]) + 1.0) * 0.5
        if factor != m.rafting_factor:                  # rebuilding K costs O(n²)
            m.set_rafting(factor, RAFT_CUTOFF)

    def measure(self) -> dict:
        m = self.model
        g = m.g
        if not np.all(np.isfinite(g)):
            raise FloatingPointError("the thickness distribution is no longer finite")
        target = self.target
        if self._target_of is not target:       # the target's cumulative fractions, once
            self._target_of, self._target_cumulative = target, cumulative_fractions(target)
        return {"g": g.copy(), "h": self._h, "open_water": float(g[0]),
                "mean_thickness": float(np.dot(g, self._h)), "day": float(m.time),
                "kernel_scale": float(m.kernel_scale), "rafting_factor": float(m.rafting_factor),
                "w1": wasserstein1_to(g, self._target_cumulative, self._dh)}

    def observe(self, now: dict) -> np.ndarray:
        v = self._vec
        v[:N_COARSE + 1] = self.coarse(now["g"])
        phase = 2.0 * math.pi * now["day"] / YEAR_DAYS
        v[N_COARSE + 1] = math.cos(phase)
        v[N_COARSE + 2] = math.sin(phase)
        v[N_COARSE + 3] = now["mean_thickness"] / MEAN_SCALE
        v[N_COARSE + 4:] = self._last_action
        return np.clip(v, self._low64, self._high64).astype(np.float32)

    def make_info(self, now: dict) -> dict:
        # fresh arrays: what an info holds is never shared with another call's
        physics = dict(now)
        physics["g"] = now["g"].copy()
        physics["h"] = now["h"].copy()
        return {"physics": physics, "target": self.target.copy(), "steps": self._steps}

    # -- task --------------------------------------------------------------------------
    def _check_episode_task(self, task: dict) -> None:
        size = self.n_classes + 1
        for name in ("target", "g0"):
            if task[name] is not None:
                g = _distribution(name, task[name], size)
                g.setflags(write=False)
                task[name] = g

    def _draw_episode(self, task, rng):
        if task["target"] is None:
            task["target"] = self._default_target
        if task["g0"] is None:
            g0 = task["target"].copy()
            g0[1:] *= np.exp(START_NOISE * rng.standard_normal(g0.size - 1))
            task["g0"] = g0 / g0.sum()
        return task

    def reward_kwargs(self) -> dict:
        return {**self.reward_params, "target": self.target, "h": self._h}

    # -- gymnasium API ----------------------------------------------------------------
    def reset(self, *, seed: int | None = None, options: dict | None = None):
        gym.Env.reset(self, seed=seed)
        self.episode = self._episode_task(options)
        self.model = ThorndikeModel(self._K, n_classes=self.n_classes, dh=self.dh,
                                    g0=self.episode["g0"])
        return self.episodes.begin(self.row)

    def _ready(self) -> bool:
        return self.model is not None

    def advance(self) -> None:
        self.model.step(self.days_per_step)

    def reward(self, action: np.ndarray, now: dict) -> float:
        if self._default_reward:           # thickness_distribution_reward, W1 already computed
            return closeness(now["w1"], 0.0, self.reward_params["distance_scale"])
        return super().reward(action, now)

    # -- rendering --------------------------------------------------------------------
    def _frame(self) -> np.ndarray:
        from .rendering import draw_itd

        return draw_itd(self._h_coarse, self.coarse(self.model.g),
                        target=self.coarse(self.target), day=self.model.time)


#: N :class:`ThicknessDistributionEnv`, stepped as one batch (:mod:`iceenvs.vector`)
ThicknessDistributionVectorEnv = vector_class(ThicknessDistributionEnv)
