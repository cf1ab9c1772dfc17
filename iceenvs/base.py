"""Shared plumbing of the environments: :class:`ControlEnv`, the base of
every environment, and :class:`HertzEnv`, of the floe tasks over the Hertz
engine.

An environment owns one engine (``self.sim``), turns an action into
forcing, advances the engine by the control interval, measures the
observables of :mod:`iceenvs.observations` and scores them with a reward
function of :mod:`iceenvs.rewards`. Its class declares its task:

* ``task_parameters`` — the task's :class:`TaskParameter` table;
* ``drawn`` — the task parameters drawn per episode from their
  ``<name>_range`` when left at ``None`` (or ``_draw_episode`` for another
  draw);
* ``make_sim(rng)`` — how to make the engine of an episode;
* ``apply_action(action)`` — how a (sanitised) action applies, as forcing;
* ``measure()`` — what is measured: the raw physical observables (a dict
  of SI values); a family measures on columns (``measure_batch``);
* ``ends(envs, nows, cols, sums, task)`` — when an episode ends: by
  default each environment's ``_succeeded(now)`` and ``_terminated(now)``;
* ``reward_fn`` and ``default_reward_params()`` — the reward;
* class attributes ``extra_features`` (entries after the common ones) and
  ``action_names``.

The step itself is not the environment's: every environment's step is that
of its batch of episodes (:class:`iceenvs.step.Episodes`), which holds the
step count, last action, measurement, observation and sums of each
episode. A single environment is a batch of one.

Data flow of one step::

    action → NaN → 0, ±inf → bound, clip → apply_action → engine advance (control interval)
      → measure (SI dict) → reward(prev, action, now), ends, and the observation

Conventions every environment keeps (see the environment docs):

* **Task parameters** are keyword arguments of :func:`gymnasium.make`
  (kept for every episode, also through a vector environment's autoreset)
  and ``reset(options=...)`` entries (for that episode only). A parameter
  whose value is ``None`` is drawn for each episode from its range.
  Unknown names raise an error that lists the valid ones.
* **Episode length** is the registered ``max_episode_steps`` (Gymnasium's
  :class:`~gymnasium.wrappers.TimeLimit`); the environments never
  truncate on their own. ``horizon=N`` adds the remaining fraction of an
  N-step episode to the observation.
* **Rewards** of the built-in tasks lie in [0, 1] every step. A failure
  (a physics failure, or the task's own failure such as broken ice) ends
  the episode with reward 0: the failed state is absorbing and worth
  nothing, so ending early never pays and no step carries a lump.
"""
from __future__ import annotations

import inspect
from dataclasses import dataclass
from typing import Any
from collections.abc import Callable

import gymnasium as gym
import numpy as np

from physics import PaperPreset
from physics.input_checks import check_range
from physics.engine import FloeEngine
from physics.hertz import hertz_time_step, scaled_contact
from physics.markdown import table_row

from .observations import FLOE_FEATURES, Feature, observation_vectors
from .snapshots import ROW, Snapshot, restore_snapshot, take_snapshot
from .step import PHYSICS_ERRORS, Episodes

__all__ = ["ControlEnv", "HertzEnv", "TaskParameter", "number", "interval",
           "sanitise_action", "sanitise_actions", "choice", "scaled_contact", "hertz_time_step",
           "REWARD_RANGE", "TIME_FEATURE", "task_table", "revised_task", "MAX_WIND", "PHYSICS_ERRORS"]

#: the reward range of the floe tasks, the default of
#: :attr:`ControlEnv.reward_bounds`; a task whose rewards leave it (the ship
#: tasks) declares its own bounds beside its reward
REWARD_RANGE = (0.0, 1.0)
#: default wind speed [m/s] of a full action of the wind-driven tasks (the
#: ``max_wind`` task parameter)
MAX_WIND = 20.0

#: the observation entry that ``horizon=N`` appends
TIME_FEATURE = Feature("time_left", "remaining fraction of the episode, 1 − t/N", "-", "none",
                       0.0, 1.0)


def sanitise_action(action, space: gym.spaces.Box) -> tuple[np.ndarray, int]:
    """The action as float64 of the space's shape, ready for a kernel, and
    the number of its entries that were not finite.

    NaN becomes 0 (no command), +inf and −inf become the upper and lower
    bound (the limit they stand for), and every entry is clipped into the
    bounds. A scalar is taken for a space of one entry; any other shape than
    the space's raises ``ValueError`` naming the expected shape."""
    a, replaced = sanitise_actions(one_action(action, space)[None], space)
    return a[0], int(replaced[0])


def one_action(action, space: gym.spaces.Box) -> np.ndarray:
    """``action`` as float64 of the space's shape (a scalar for a space of
    one entry); ``ValueError`` naming the expected shape for another."""
    a = np.array(action, dtype=np.float64)
    if a.shape != space.shape:
        if a.ndim == 0 and space.shape == (1,):
            return a.reshape(1)
        raise ValueError(f"an action of shape {a.shape}; this environment takes actions "
                         f"of shape {space.shape} (its action_space is {space})")
    return a


def sanitise_actions(actions: np.ndarray, space: gym.spaces.Box) -> tuple[np.ndarray, np.ndarray]:
    """:func:`sanitise_action` of a batch: ``actions`` (M,) + the space's
    shape, float64; returns the sanitised copy and the number of non-finite
    entries of each action (M,)."""
    a = np.array(actions, dtype=np.float64)
    if np.isfinite(a).all():
        # np.clip's result, without its wrapper's cost (a step of a cheap task feels it)
        return (np.minimum(np.maximum(a, space.low), space.high),
                np.zeros(a.shape[0], dtype=np.int64))
    bad = ~np.isfinite(a)
    a[np.isnan(a)] = 0.0
    return np.clip(a, space.low, space.high), bad.reshape(a.shape[0], -1).sum(axis=1)


# -- task parameters ---------------------------------------------------------------------------

@dataclass(frozen=True)
class TaskParameter:
    """One parameter of a task.

    It is set for every episode as a keyword of :func:`gymnasium.make`
    (``gym.make(id, target=0.85)``) and for one episode as an entry of
    ``reset(options=...)``. ``check(name, value)`` validates a value and
    returns it converted (raising ``ValueError`` with the name, the value
    and the allowed range); ``None`` means "drawn for every episode from
    its range" where ``meaning`` says so.
    """
    name: str
    default: Any
    meaning: str
    check: Callable[[str, Any], Any]


def number(low=None, high=None, *, low_open: bool = False, high_open: bool = False,
           optional: bool = False) -> Callable[[str, Any], Any]:
    """A check for a finite number in a range (``None`` allowed when
    ``optional``)."""
    def check(name, value):
        if value is None and optional:
            return None
        if isinstance(value, bool):
            raise ValueError(f"{name} must be a number, got {value!r}")
        check_range(name, value, low, high, low_open=low_open, high_open=high_open)
        return float(value)
    return check


def interval(low=None, high=None, *, low_open: bool = False,
             high_open: bool = False) -> Callable[[str, Any], Any]:
    """A check for a range ``(lo, hi)``, ``lo <= hi``, both ends inside
    [low, high]."""
    def check(name, value):
        try:
            lo, hi = value
        except (TypeError, ValueError):
            raise ValueError(f"{name} must be a pair (low, high), got {value!r}") from None
        ends = tuple(number(low, high, low_open=low_open, high_open=high_open)(f"{name}[{k}]", v)
                     for k, v in enumerate((lo, hi)))
        if ends[0] > ends[1]:
            raise ValueError(f"{name} must have low <= high, got {value!r}")
        return ends
    return check


def choice(*options: str) -> Callable[[str, Any], Any]:
    """A check for one of the strings ``options``."""
    def check(name, value):
        if value not in options:
            raise ValueError(f"{name} must be one of {list(options)}, got {value!r}")
        return value
    return check


def revised_task(params, changed: dict | None = None, defaults: dict | None = None,
                 added=()) -> tuple:
    """Another task's parameters ``params`` revised for a task that builds
    on it: ``changed`` maps a name to its new ``(meaning, check)``,
    ``defaults`` a name to its new default, and ``added`` parameters come
    last. Raises ``ValueError`` for a name ``params`` does not have."""
    changed, defaults = dict(changed or {}), dict(defaults or {})
    names = {p.name for p in params}
    unknown = sorted((set(changed) | set(defaults)) - names)
    if unknown:
        raise ValueError(f"no task parameters {unknown} to revise; there are {sorted(names)}")
    out = []
    for p in params:
        meaning, check = changed.get(p.name, (p.meaning, p.check))
        out.append(TaskParameter(p.name, defaults.get(p.name, p.default), meaning, check))
    return tuple(out) + tuple(added)


def task_table(params) -> str:
    """The "Task parameters" section of an environment's docstring: how to
    set them, then their Markdown table."""
    lines = ["Keywords of `gymnasium.make` (kept for every episode) and entries of",
             "    `reset(options=...)` (this episode only):", "",
             "| name | default | meaning |", "|---|---|---|"]
    for p in params:
        default = "None" if p.default is None else (
            f"({p.default[0]:g}, {p.default[1]:g})" if isinstance(p.default, tuple)
            else f'"{p.default}"' if isinstance(p.default, str) else f"{p.default:g}")
        lines.append(table_row([f"`{p.name}`", default, p.meaning]))
    return "\n".join(lines)


# -- the control loop ------------------------------------------------------------------------

def _check_horizon(horizon) -> int | None:
    if horizon is None:
        return None
    if isinstance(horizon, bool) or not isinstance(horizon, (int, np.integer)) or horizon < 1:
        raise ValueError(f"horizon must be None or an integer >= 1 (the episode's "
                         f"max_episode_steps), got {horizon!r}")
    return int(horizon)


class ControlEnv(gym.Env):
    """The control loop every environment of the suite shares.

    One step, written once for every environment in its batch of episodes
    (:class:`iceenvs.step.Episodes`; a single environment is a batch of one):
    sanitise the action → ``apply_action`` → ``advance`` (the engines) →
    ``measure`` (raw SI dict) → ``reward`` → ``ends`` → the observation
    (``observe``) and the info (``make_info``). A physics failure
    (FloatingPointError, RuntimeError, ValueError), a non-finite reward or
    the task's failure (``_terminated``) ends the episode with
    ``failure_reward`` and, for a physics failure or a non-finite reward,
    ``info["error"]``; a task done (``_succeeded``, a goal reached) ends it
    with the step's reward.
    Episodes are truncated by Gymnasium's ``TimeLimit`` (the registered
    ``max_episode_steps``), never by the environment itself.

    An environment over a floe engine (``self.sim``) provides ``make_sim``,
    ``apply_action``, ``measure`` and ``_frame`` (an RGB array); one over
    another model (the thickness distribution) builds it in ``reset``, then
    begins the episode in its batch (``self.episodes.begin(self.row)``),
    and provides ``_ready`` (a model exists), ``advance``, ``observe`` and
    ``make_info`` as well. The environments'
    classes are at most three deep: this class, a family (:class:`HertzEnv`,
    :class:`iceenvs.ship_env.ShipEnv`) and the task.

    The reward contract: every step's reward, a failure's included, lies in
    :attr:`reward_bounds`. A task declares both with its reward: the floe
    tasks keep the defaults ([0, 1], a failure paid 0); a task whose reward
    leaves them overrides ``reward_bounds`` and ``failure_reward``
    together (:class:`iceenvs.ship_env.ShipEnv`), and
    :func:`iceenvs.checks.check_rewards` holds every registered id to it.

    Arguments common to the floe environments:

    * ``n_floes`` (int or None): number of floes; None for an environment
      that draws its own field (``own_field``), whose count comes with each
      episode's field (``n_floes`` is 0 until the first reset);
    * ``preset`` (PaperPreset): parameter table (FSD, material, forcing);
    * ``control_interval`` (float): model seconds per env step;
    * ``reward_fn`` (callable, optional): ``reward(prev, action, now, **params)``;
    * ``reward_params`` (dict, optional): overrides of the task's reward weights;
    * ``stiffness_scale`` (float): multiplies Young's modulus (Hertz envs); < 1
      trades contact stiffness for a longer time step (faster training);
    * ``cluster_gap`` (float): largest gap [m] between two floes of a cluster;
    * ``horizon`` (int, optional): adds ``time_left`` = 1 − t/horizon to the
      observation (pass the episode's ``max_episode_steps``);
    * ``colour_scale`` (float): speed [m/s] at the top of the frames' colour bar;
    * ``render_mode``: None, "rgb_array" or "human";
    * ``**task``: the task parameters of the environment (its table).
    """

    metadata = {"render_modes": ["human", "rgb_array"], "render_fps": 10}
    #: the reward of a step that ends the episode by a failure (the task's,
    #: the physics' or a non-finite reward); within :attr:`reward_bounds`
    failure_reward = 0.0
    task_parameters: tuple[TaskParameter, ...] = ()
    #: episode task values passed to the reward function with ``reward_params``
    reward_task_keys: tuple[str, ...] = ()
    #: task parameters drawn uniformly from their ``<name>_range``, in this order
    drawn: tuple[str, ...] = ()
    _renderer = None
    horizon = None
    #: what an episode changes (:mod:`iceenvs.snapshots`): the members a
    #: snapshot holds; each subclass lists the ones it adds
    episode_members: tuple[str, ...] = ("_np_random", "_np_random_seed", "episode", "sim")
    #: what changes in an episode but is no state of it: caches that a restore
    #: rebuilds, work buffers written whole before they are read, and the
    #: batch of episodes the environment is a row of (whose row a snapshot holds)
    episode_caches: tuple[str, ...] = ("episodes", "row")
    #: settings of the frames, which a snapshot's configuration check ignores
    render_settings: tuple[str, ...] = ("render_mode", "colour_scale", "_renderer")

    #: the observation entries every environment of the family has
    base_features: tuple[Feature, ...] = FLOE_FEATURES
    extra_features: tuple[Feature, ...] = ()
    action_names: tuple[str, ...] = ()
    reward_fn: Callable = None
    colour_label = "speed [m/s]"
    #: the environment draws each episode's field itself, and with it the number
    #: of floes (it passes ``n_floes=None``)
    own_field = False

    #: the largest relative speed at impact [m/s] the time step must resolve
    impact_speed = 1.0

    # -- how the family steps in a batch (:class:`iceenvs.step.Episodes`) -------------------
    #: the engines of a vector environment advance together, in one compiled
    #: call (:func:`physics.hertz.advance_together`)
    engines_together = False
    #: ... and a single environment's engine too (else it advances on its own)
    single_together = False
    #: the family measures a batch on columns (``measure_batch``, ``measure_names``)
    measures_in_batch = False
    #: a batch measured on columns is rewarded on columns (the class's own reward)
    rewards_on_columns = False
    #: ... and observed on columns (``feature_columns``)
    observes_on_columns = False
    #: the columns of an episode's running sums (the batch's ``sums``)
    sum_columns: tuple[str, ...] = ()

    def __init__(self, *, n_floes: int | None, preset: PaperPreset, control_interval: float,
                 reward_fn=None, reward_params: dict | None = None,
                 stiffness_scale: float = 1.0, cluster_gap: float = 0.1,
                 horizon: int | None = None, colour_scale: float = 0.5,
                 render_mode: str | None = None, **task):
        if n_floes is not None or not self.own_field:
            if isinstance(n_floes, bool) or not isinstance(n_floes, (int, np.integer)):
                raise ValueError(f"n_floes must be an integer >= 2, got {n_floes!r}")
            check_range("n_floes", n_floes, 2, None)
        check_range("control_interval", control_interval, 0.0, None, low_open=True)
        check_range("cluster_gap", cluster_gap, 0.0, None)
        check_range("colour_scale", colour_scale, 0.0, None, low_open=True)
        if not isinstance(preset, PaperPreset):
            raise TypeError(f"preset must be a PaperPreset (e.g. physics.HERMAN2013), "
                            f"got {type(preset).__name__}")
        self._set_render_mode(render_mode)
        self._init_task(task)
        self.n_floes = 0 if n_floes is None else int(n_floes)
        self.preset = preset
        self.control_interval = float(control_interval)
        self.stiffness_scale = float(stiffness_scale)
        self.contact = scaled_contact(preset.contact, stiffness_scale)
        self.cluster_gap = float(cluster_gap)
        self.horizon = _check_horizon(horizon)
        self.colour_scale = float(colour_scale)
        if reward_fn is not None:
            if not callable(reward_fn):
                raise TypeError("reward_fn must be callable as reward(prev, action, now, **params)")
            self.reward_fn = reward_fn
        else:
            self.reward_fn = type(self).reward_fn
        self._init_reward_params(self.default_reward_params(), reward_params,
                                 custom=reward_fn is not None)

        self.features = self.base_features + self.extra_features
        if self.horizon is not None:
            self.features = self.features + (TIME_FEATURE,)
        n_act = self.action_space.shape[0]
        low = np.array([f.low for f in self.features] + [-1.0] * n_act, dtype=np.float32)
        high = np.array([f.high for f in self.features] + [1.0] * n_act, dtype=np.float32)
        self.observation_space = gym.spaces.Box(low, high, dtype=np.float32)
        #: the episode's engine (:meth:`make_sim`); the code shared here uses only
        #: :class:`~physics.engine.FloeEngine`, an environment may use more of its engine
        self.sim: FloeEngine | None = None
        Episodes([self], single=True)

    @property
    def reward_bounds(self) -> tuple[float, float]:
        """(lowest, highest) reward of one step, a failure's included:
        :data:`REWARD_RANGE` unless the task declares its own."""
        return REWARD_RANGE

    def _set_render_mode(self, render_mode: str | None) -> None:
        if render_mode is not None and render_mode not in self.metadata["render_modes"]:
            raise ValueError(f"render_mode must be one of {self.metadata['render_modes']} or "
                             f"None, got {render_mode!r}")
        self.render_mode = render_mode

    # -- task parameters --------------------------------------------------------------------
    @classmethod
    def valid_arguments(cls) -> list[str]:
        """Every keyword :func:`gymnasium.make` accepts for this environment:
        the constructor's arguments and the task parameters."""
        names = set()
        for klass in cls.__mro__:
            init = klass.__dict__.get("__init__")
            if init is None:
                continue
            for p in inspect.signature(init).parameters.values():
                if p.name != "self" and p.kind not in (p.VAR_KEYWORD, p.VAR_POSITIONAL):
                    names.add(p.name)
        return sorted(names | {p.name for p in cls.task_parameters})

    @classmethod
    def _check_task(cls, values: dict, what: str) -> dict:
        params = {p.name: p for p in cls.task_parameters}
        unknown = sorted(set(values) - set(params))
        if unknown:
            raise ValueError(f"unknown {what} {unknown} for {cls.__name__}; valid: "
                             f"{sorted(params)}")
        return {name: params[name].check(name, value) for name, value in values.items()}

    def _init_reward_params(self, defaults: dict, reward_params: dict | None,
                            custom: bool) -> None:
        """``self.reward_params``: the task's ``defaults`` updated by
        ``reward_params``; names the task does not have are refused unless
        the reward function is a ``custom`` one."""
        if reward_params is not None and not isinstance(reward_params, dict):
            raise TypeError(f"reward_params must be a dict, got {type(reward_params).__name__}")
        unknown = set(reward_params or ()) - set(defaults)
        if unknown and not custom:
            raise ValueError(f"unknown reward parameters {sorted(unknown)}; this task has "
                             f"{sorted(defaults)} (task parameters such as a target are "
                             f"arguments of their own)")
        self.reward_params = {**defaults, **(reward_params or {})}

    def _init_task(self, given: dict) -> None:
        """Keep the task parameters given to the constructor (``TypeError``
        for a name that is neither an argument nor a task parameter)."""
        names = {p.name for p in self.task_parameters}
        unknown = sorted(set(given) - names)
        if unknown:
            raise TypeError(f"{type(self).__name__} got unknown arguments {unknown}; valid "
                            f"arguments: {', '.join(self.valid_arguments())}")
        self.task = {p.name: p.check(p.name, p.default) for p in self.task_parameters}
        self.task.update(self._check_task(given, "arguments"))
        self._check_episode_task(self.task)
        self.episode = dict(self.task)

    def _check_episode_task(self, task: dict) -> None:
        """Checks across parameters (e.g. a range against a limit); raise
        ``ValueError``."""

    def _episode_task(self, options: dict | None) -> dict:
        """The task of a new episode: the constructor's parameters, then the
        options of this episode, then the values drawn from their ranges."""
        task = dict(self.task)
        task.update(self._check_task(dict(options or {}), "reset options"))
        self._check_episode_task(task)
        return self._draw_episode(task, self.np_random)

    def _draw_episode(self, task: dict, rng: np.random.Generator) -> dict:
        """Replace the ``None`` entries of ``task`` by values drawn with ``rng``:
        each name of ``drawn`` uniformly from its ``<name>_range``. Every one
        is drawn, given or not and in a fixed order, so that a seed gives
        the same episode whichever of them is given."""
        for name in self.drawn:
            value = float(rng.uniform(*self._draw_range(name, task)))
            if task[name] is None:
                task[name] = value
        return task

    def _draw_range(self, name: str, task: dict) -> tuple:
        """The range a drawn task parameter ``name`` is drawn from: its
        ``<name>_range``."""
        return task[f"{name}_range"]

    # -- the task ---------------------------------------------------------------------------
    def apply_action(self, action: np.ndarray) -> None:
        """Apply the sanitised ``action`` (as forcing, commands, ...)."""
        raise NotImplementedError

    def measure(self) -> dict:
        """The raw physical observables now (a dict of SI values)."""
        raise NotImplementedError

    def ends(self, envs, nows, cols, sums, task) -> tuple[np.ndarray, np.ndarray]:
        """(succeeded, failed), a boolean each (arrays or lists), of the
        environments ``envs`` (of this class and configuration) that
        measured ``nows`` (dicts; ``cols``, ``sums`` and ``task``: the
        columns of a family measured on columns, else None): by default each
        one's ``_succeeded(now)`` and ``_terminated(now)``."""
        return ([bool(env._succeeded(now)) for env, now in zip(envs, nows)],
                [bool(env._terminated(now)) for env, now in zip(envs, nows)])

    def _terminated(self, now: dict) -> bool:
        return False

    def _succeeded(self, now: dict) -> bool:
        """The task is done (a goal reached): the episode ends with the
        step's own reward, unlike a failure."""
        return False

    def reward_kwargs(self) -> dict:
        """The keywords of the reward function: the reward parameters and the
        episode's values of ``reward_task_keys``."""
        return {**self.reward_params, **{k: self.episode[k] for k in self.reward_task_keys}}

    def reward(self, action: np.ndarray, now: dict) -> float:
        """The reward of a step that took ``action`` and measured ``now``."""
        return float(self.reward_fn(self._prev, action, now, **self.reward_kwargs()))

    def _frame(self) -> np.ndarray:
        raise NotImplementedError

    def time_left(self) -> float:
        """The remaining fraction of a ``horizon``-step episode."""
        return max(0.0, 1.0 - self._steps / self.horizon)

    # -- to be provided by subclasses ------------------------------------------------
    def default_reward_params(self) -> dict:
        return {}

    def make_sim(self, rng: np.random.Generator) -> FloeEngine:
        """The engine of a new episode, its floes drawn with ``rng``."""
        raise NotImplementedError

    def _ready(self) -> bool:
        return self.sim is not None

    def advance(self) -> None:
        """Advance the engine by the control interval (a batch whose family
        advances its engines together does it for all of them at once)."""
        self.sim.advance(self.control_interval)

    # -- gymnasium API ----------------------------------------------------------------
    def reset(self, *, seed: int | None = None, options: dict | None = None):
        super().reset(seed=seed)
        self.episode = self._episode_task(options)
        self.sim = self.make_sim(self.np_random)
        return self.episodes.begin(self.row)

    def observe(self, now: dict) -> np.ndarray:
        """The observation of the measurement ``now``."""
        if self.horizon is not None:
            now = {**now, "time_left": self.time_left()}
        row = np.array([[float(now[f.name]) for f in self.features]])
        return observation_vectors(row, self.features, self._last_action[None])[0]

    def make_info(self, now: dict) -> dict:
        """The info of the measurement ``now``."""
        return {"physics": dict(now), "time": float(self.sim.time), "steps": self._steps,
                "task": dict(self.episode)}

    # -- frames -----------------------------------------------------------------------
    def _frame_text(self) -> list[str]:
        """Lines of text on a frame: time, concentration and the task."""
        now = self._prev
        return [f"t = {self.sim.time:.0f} s", f"A = {now['concentration']:.3f}"]

    def _frame_arrow(self):
        """Arrows on a frame (see :func:`iceenvs.rendering.annotate`)."""
        return None

    # -- the loop -----------------------------------------------------------------------------
    @property
    def last_measurement(self) -> dict | None:
        """The raw physical observables (SI units) of the last reset or step,
        from which the observation and the reward were made; ``None`` before
        the first reset. Controllers that read the physics instead of the
        observation use it."""
        return self._prev

    # -- the episode's state: a row of its batch (:class:`iceenvs.step.Episodes`) -----------
    def join(self, episodes: Episodes, row: int) -> None:
        """Make this environment row ``row`` of the batch ``episodes`` (a
        native vector environment's; at construction its own batch of one)."""
        self.episodes = episodes
        self.row = int(row)

    @property
    def _steps(self) -> int:
        return int(self.episodes.steps[self.row])

    @property
    def _last_action(self) -> np.ndarray:
        return self.episodes.last_action[self.row]

    @property
    def _prev(self) -> dict | None:
        return self.episodes.prev[self.row]

    @property
    def _obs(self):
        return self.episodes.obs[self.row]

    def step(self, action):
        """One step: the step of the environment's batch of one
        (:meth:`iceenvs.step.Episodes.step`)."""
        if not self._ready():
            raise RuntimeError("call reset() before step()")
        if not self.episodes.single:
            raise RuntimeError("this environment is a sub-environment of a vector environment: "
                               "step the vector environment")
        actions, replaced = sanitise_actions(one_action(action, self.action_space)[None],
                                             self.action_space)
        obs, reward, terminated, info = self.episodes.step(actions, replaced)
        return obs, float(reward[0]), bool(terminated[0]), False, info

    # -- snapshots ----------------------------------------------------------------------------
    def snapshot(self) -> Snapshot:
        """The state of the episode now, as a :class:`~iceenvs.snapshots.Snapshot`
        that :meth:`restore` brings back: the engine (floes, contact
        history, neighbour lists, ship, box, time), the drawn task, the step
        count, the last measurement and observation, the episode's sums and
        the random generator (which the next episode's draw reads). After a
        restore the same actions give the same observations, rewards,
        terminations and infos, bit for bit. Copies: later steps leave the
        snapshot as it was. The configuration is not in it.

        Raises ``RuntimeError`` before the first ``reset``."""
        if not self._ready():
            raise RuntimeError("call reset() before snapshot(): there is no episode to save")
        return take_snapshot(self)

    def restore(self, snapshot: Snapshot) -> None:
        """Bring back the episode of ``snapshot`` (taken by :meth:`snapshot` of
        this environment or of another made with the same arguments), as it
        was when it was taken; the snapshot stays as it is and can be
        restored again. Gymnasium's ``TimeLimit`` wrapper counts its steps
        apart: restore on ``env.unwrapped`` and step it there (its own step
        count, ``info["steps"]``, is restored).

        Raises ``RuntimeError`` before the first ``reset``, ``TypeError``
        for anything but a snapshot and ``ValueError`` for a snapshot of
        another environment class or configuration."""
        if not self._ready():
            raise RuntimeError("call reset() before restore(): restore into an environment "
                               "that has begun an episode")
        self._set_members(restore_snapshot(self, snapshot))

    def _set_members(self, state: dict) -> None:
        """Set the episode members ``state`` (fresh copies) and the row of
        the batch; a subclass rebuilds its caches (:attr:`episode_caches`)."""
        row = state.pop(ROW)
        self.__dict__.update(state)
        self.episodes.set_row(self.row, row)

    # -- rendering ----------------------------------------------------------------------------
    def render(self):
        if self.render_mode is None:
            gym.logger.warn("render() called without a render_mode; pass render_mode="
                            "'rgb_array' or 'human' to gymnasium.make")
            return None
        if not self._ready():
            raise RuntimeError("call reset() before render()")
        frame = self._frame()
        if self.render_mode == "rgb_array":
            return frame
        from .rendering import Window

        if self._renderer is None:
            self._renderer = Window(type(self).__name__, frame.shape[1], frame.shape[0],
                                    self.metadata["render_fps"])
        self._renderer.show(frame)
        return None

    def close(self):
        if self._renderer is not None:
            self._renderer.close()
            self._renderer = None


class HertzEnv(ControlEnv):
    """Base of the environments over the Hertz engine
    (:class:`physics.HertzSimulation`): measurement from the engine's
    contacts and Love–Weber stress, frames with force chains.

    ``impact_speed`` [m/s] is the largest relative speed at impact the time
    step must resolve (wind of 20 m/s drives floes at about 0.5 m/s).
    """

    episode_members = ("_contacts",)
    #: a native vector environment advances its engines in one compiled call; a
    #: single environment's engine advances on its own (:meth:`advance`)
    engines_together = True

    def _hertz_sim(self, field, box, forcing):
        from physics import HertzSimulation

        dt = hertz_time_step(field, box, self.contact, self.impact_speed,
                             self.preset.time_step,
                             self.stiffness_scale)
        return HertzSimulation(field, box, self.contact, forcing, dt=dt,
                               impact_speed=self.impact_speed, parallel=False, skip_resting=True)

    def _contact_physics(self) -> dict:
        from physics.observables import stress

        from .observations import floe_physics

        sim = self.sim
        self._contacts = sim.contacts()
        area = sim.box.area
        st = stress(self._contacts, area, n_floes=sim.n_floes, per_floe=False)
        mobile = ~sim.frozen
        return floe_physics(sim.positions, sim.velocities, sim.masses, sim.radii, sim.box,
                            self._contacts, st.tensor, area, mobile,
                            cluster_gap=self.cluster_gap)

    def measure(self) -> dict:
        return self._contact_physics()

    def _frame(self) -> np.ndarray:
        from .rendering import annotate, draw_floes

        sim = self.sim
        c = self._contacts
        picture = draw_floes(sim.positions, sim.radii, (sim.box.lx, sim.box.ly),
                             np.hypot(sim.velocities[:, 0], sim.velocities[:, 1]),
                             frozen=sim.frozen, contact_i=c.i, contact_j=c.j,
                             contact_force=c.normal_force, speed_scale=self.colour_scale)
        return annotate(picture, colour_bar=(self.colour_label, 0.0, self.colour_scale),
                        arrow=self._frame_arrow(), text=self._frame_text())
