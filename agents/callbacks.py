"""Training callbacks: the physics metrics of ``info["physics"]`` logged
next to the returns (and written to ``metrics.csv``), a tqdm progress
bar and a wall-clock budget."""
from __future__ import annotations

import csv
import math
import time
from collections import deque
from pathlib import Path

import numpy as np
from stable_baselines3.common.callbacks import BaseCallback

from iceenvs.facts import env_facts

__all__ = ["PhysicsMetricsCallback", "TqdmCallback", "TimeBudgetCallback",
           "SaveNormalizationOnBest", "UpdateLog"]


class PhysicsMetricsCallback(BaseCallback):
    """Log the task's physics metrics per finished episode.

    For every finished episode of every sub-environment, the final value
    and the episode mean of each metric of the environment's facts
    (:meth:`iceenvs.facts.EnvFacts.logged_metrics`)
    are kept; at the end of each rollout the means over the last
    ``window`` episodes are recorded as ``physics/final_<name>`` and
    ``physics/mean_<name>`` (next to SB3's ``rollout/ep_rew_mean``). Each
    episode is also a row of the CSV file ``csv_path``: timesteps, env
    index, return and length (from :class:`VecMonitor`), then the final and
    mean values.

    Parameters
    ----------
    env_id : str
        Environment id (chooses the metrics).
    csv_path : path
        The CSV file to write (created, header first).
    window : int
        Number of recent episodes averaged in the logs.
    """

    def __init__(self, env_id: str, csv_path: str | Path, window: int = 20, verbose: int = 0):
        super().__init__(verbose)
        self.env_id = env_id
        self._logged_metrics = env_facts(env_id).logged_metrics
        self.csv_path = Path(csv_path)
        self.window = window
        self._file = None
        self._writer = None
        self._fields = None
        self._sums = None
        self._counts = None
        self.recent: deque = deque(maxlen=window)
        self.episodes = 0

    def _on_training_start(self) -> None:
        n = self.training_env.num_envs
        self._sums = [dict() for _ in range(n)]
        self._counts = np.zeros(n, dtype=int)
        self._file = open(self.csv_path, "w", newline="")

    def _on_step(self) -> bool:
        infos = self.locals.get("infos", ())
        dones = self.locals.get("dones", np.zeros(len(infos), dtype=bool))
        for i, info in enumerate(infos):
            values = self._logged_metrics(info)
            sums = self._sums[i]
            for name, v in values.items():
                sums[name] = sums.get(name, 0.0) + v
            self._counts[i] += 1
            if dones[i]:
                self._episode_end(i, info, values)
        return True

    def _episode_end(self, i: int, info: dict, final: dict) -> None:
        count = max(int(self._counts[i]), 1)
        row = {"timesteps": self.num_timesteps, "env": i}
        ep = info.get("episode", {})
        row["return"] = float(ep.get("r", math.nan))
        row["length"] = int(ep.get("l", count))
        row.update({f"final_{k}": v for k, v in final.items()})
        row.update({f"mean_{k}": s / count for k, s in self._sums[i].items()})
        if self._writer is None:
            self._fields = list(row)
            self._writer = csv.DictWriter(self._file, fieldnames=self._fields,
                                          extrasaction="ignore", restval="")
            self._writer.writeheader()
        self._writer.writerow(row)
        self._file.flush()
        self.recent.append(row)
        self.episodes += 1
        self._sums[i] = {}
        self._counts[i] = 0

    def _on_rollout_end(self) -> None:
        if not self.recent:
            return
        keys = [k for k in self.recent[-1] if k.startswith(("final_", "mean_"))]
        for k in keys:
            values = [r[k] for r in self.recent if k in r and math.isfinite(r[k])]
            if values:
                self.logger.record(f"physics/{k}", float(np.mean(values)))
        self.logger.record("physics/episodes", self.episodes)

    def _on_training_end(self) -> None:
        if self._file is not None:
            self._file.close()
            self._file = None


class TqdmCallback(BaseCallback):
    """A tqdm progress bar over the training timesteps, with the mean
    return of the recent episodes in its postfix.

    Parameters
    ----------
    total : int
        Timesteps of the run.
    disable : bool
        Hide the bar.
    """

    def __init__(self, total: int, disable: bool = False):
        super().__init__(0)
        self.total = total
        self.disable = disable
        self.bar = None

    def _on_training_start(self) -> None:
        from tqdm.auto import tqdm

        self.bar = tqdm(total=self.total, unit="step", desc="training",
                        disable=self.disable, dynamic_ncols=True)

    def _on_step(self) -> bool:
        n = self.training_env.num_envs
        self.bar.update(min(n, self.total - self.bar.n))
        buf = self.model.ep_info_buffer
        if buf and self.n_calls % 50 == 0:
            self.bar.set_postfix(ep_return=f"{np.mean([e['r'] for e in buf]):.3g}",
                                 refresh=False)
        return True

    def _on_training_end(self) -> None:
        if self.bar is not None:
            self.bar.close()


class UpdateLog(BaseCallback):
    """Keeps what each update of an on-policy algorithm logged under
    ``keys`` (e.g. ``"train/explained_variance"``, the share of the
    returns' variance the critic's values explained before the update), in
    :attr:`values`, one list per key, update by update.

    An update's values are read when the next rollout ends, or when the
    training ends, before SB3's logger writes and clears them; each update
    (by SB3's ``train/n_updates``) is kept once, so one instance may follow
    several ``learn`` calls of one model."""

    def __init__(self, keys=("train/explained_variance",)):
        super().__init__(0)
        self.keys = tuple(keys)
        self.values: dict[str, list[float]] = {k: [] for k in self.keys}
        self._last = None

    def _keep(self) -> None:
        logged = self.model.logger.name_to_value
        update = logged.get("train/n_updates")
        if self.keys[0] in logged and update is not None and update != self._last:
            self._last = update
            for key in self.keys:
                self.values[key].append(float(logged.get(key, math.nan)))

    def _on_rollout_end(self) -> None:
        self._keep()

    def _on_step(self) -> bool:
        return True

    def _on_training_end(self) -> None:
        self._keep()


class TimeBudgetCallback(BaseCallback):
    """Stop training once ``minutes`` of wall-clock time have passed since
    it started, or since ``started`` (a ``time.perf_counter`` value, e.g.
    before a warm start that belongs to the budget); checked every step,
    the run then saves its model as at the end of its timesteps."""

    def __init__(self, minutes: float, started: float | None = None):
        super().__init__(0)
        if not (math.isfinite(minutes) and minutes > 0):
            raise ValueError(f"minutes must be a positive number, got {minutes!r}")
        self.seconds = 60.0 * float(minutes)
        self._started = started
        self._start = None

    def _on_training_start(self) -> None:
        self._start = time.perf_counter() if self._started is None else self._started

    #: why the callback stopped training (``None`` while it has not)
    reason: str | None = None

    def _on_step(self) -> bool:
        if time.perf_counter() - self._start < self.seconds:
            return True
        # said by the trainer once the progress bar is closed: a line printed
        # under a live bar is drawn over by it
        self.reason = f"its budget of {self.seconds / 60:g} minutes"
        return False


class SaveNormalizationOnBest(BaseCallback):
    """Called by :class:`EvalCallback` on a new best mean return: save the
    training stack's normalisation statistics beside the best model, so
    that ``RUN_DIR@best`` observes as it was evaluated (nothing without
    normalisation)."""

    def __init__(self, path: str | Path):
        super().__init__(0)
        self.path = Path(path)

    def _on_step(self) -> bool:
        from stable_baselines3.common.vec_env import VecNormalize

        env = self.model.get_vec_normalize_env()
        if isinstance(env, VecNormalize):
            self.path.parent.mkdir(parents=True, exist_ok=True)
            env.save(str(self.path))
        return True
