"""See what a policy did on one field: ``python -m agents.frames``.

The policy plays one episode from ``reset(seed=SEED)``, the leaderboard's
field k when SEED is its ``--seed`` + k (``10000 + k`` by default) and
``--concentration`` its concentration, and the environment draws frames
along the way (``render_mode="rgb_array"``). A ship environment draws the
``follow`` view (a window that follows the ship, to scale, with the ice
coloured by thickness class, the leads, the track and the course a
planner shows) or the ``overview`` (the whole channel). Written to
``--out`` (default ``runs/frames/<env>_<policy>_<seed>``):

* ``frame_<step>.png`` — the frames, every ``--every`` steps (the first
  and the last step included) or at the model times of ``--times``;
* ``contact_sheet.png`` — the frames side by side, each with its step and
  time, above the whole channel at the end, with the episode's summary;
* ``overview.png`` — the whole channel at the end, with the ship's whole
  track.

::

    python -m agents.frames POLICY [--env iceenvs/ShipNavigation-v1] [--seed 10000]
        [--concentration A] [--env-kwargs key=value ...] [--every K | --times t1,t2,...]
        [--view follow|overview] [--out DIR] [--no-progress]

POLICY is what the leaderboard takes: a baseline's name (``straight``,
``swath``, ``lattice``, ...), a policy of one's own (``module:Class``,
``path/to/file.py:Class?key=value``; :mod:`agents.policy`) or a run of
:mod:`agents.train` (``RUN_DIR`` or ``RUN_DIR@STEPS``, played with the
run's own :data:`agents.rollouts.AGENT_KWARGS`, as the leaderboard plays
it).
"""
from __future__ import annotations

import argparse
import math
import re
import sys
from pathlib import Path

import numpy as np

from .leaderboard import DEFAULT_ENV

__all__ = ["play_frames", "contact_sheet", "episode_summary", "default_out", "policy_label",
           "build_parser", "main", "DEFAULT_FRAMES", "DEFAULT_STEPS_PER_FRAME", "SHEET_TILES"]

#: frames a ship's straight transit is divided into by default (every 34
#: steps on the leaderboard's kilometre of ice, 275 steps)
DEFAULT_FRAMES = 8
#: steps between frames by default where there is no straight transit to divide
DEFAULT_STEPS_PER_FRAME = 40
#: the most frames the contact sheet shows (evenly spread, the first and last kept)
SHEET_TILES = 12
#: the colours of the contact sheet (those of the frames' panels)
SHEET_BACKGROUND = "#1c1e24"
SHEET_TEXT = "#e8e8e8"
#: width [px] of the contact sheet
SHEET_WIDTH = 1200

_FRAME_FILE = re.compile(r"^frame_\d+\.png$")


# -- the policy --------------------------------------------------------------------------
def policy_label(policy: str) -> str:
    """A name for files of ``policy``: a baseline's name, the class (and
    arguments) of a reference, a run directory's name (and ``@STEPS``)."""
    from .policy import is_reference

    if is_reference(policy):
        text, _, query = policy.partition("?")
        label = text.rpartition(":")[2] + (f"-{query}" if query else "")
    else:
        run_dir, at, steps = policy.partition("@")
        label = Path(run_dir).name + (f"@{steps}" if at else "")
    return re.sub(r"[^\w.=@+-]+", "-", label).strip("-") or "policy"


def default_out(env_id: str, policy: str, seed: int, concentration: float | None = None) -> Path:
    """``runs/frames/<env name>_<policy label>_<seed>[_A<concentration>]``."""
    from .metrics import env_name

    parts = [env_name(env_id), policy_label(policy), str(seed)]
    if concentration is not None:
        parts.append(f"A{concentration:g}")
    return Path("runs") / "frames" / "_".join(parts)


def _is_run(policy: str) -> bool:
    """Whether ``policy`` reads as a run directory (``RUN_DIR[@STEPS]``)."""
    run_dir = policy.partition("@")[0]
    return "@" in policy or "/" in policy or "\\" in policy or Path(run_dir).is_dir()


# -- the episode -------------------------------------------------------------------------
def _model_time(env, step: int) -> float:
    """The model time [s] of ``env`` (its engine's clock, else the steps
    times the control interval)."""
    u = env.unwrapped
    t = getattr(getattr(u, "sim", None), "time", None)
    if t is not None:
        return float(t)
    return step * float(getattr(u, "control_interval", 1.0))


def _picture_rows(env, frame: np.ndarray) -> int:
    """The rows of ``frame`` above its panel: the picture of a ship view
    (:meth:`iceenvs.ship_env.ShipEnv.view_box`), the whole frame
    otherwise."""
    u = env.unwrapped
    if getattr(u, "view", None) is None or not hasattr(u, "view_box"):
        return frame.shape[0]
    return min(frame.shape[0], int(u.view_box().picture_size[1]))


def _default_every(env) -> int:
    """About :data:`DEFAULT_FRAMES` frames over a straight transit of a ship
    environment (its goal distance at full speed); else
    :data:`DEFAULT_STEPS_PER_FRAME`."""
    u = env.unwrapped
    try:
        metres = float(u.goal_distance) / (float(u.max_speed) * float(u.control_interval))
    except (AttributeError, TypeError, ValueError, ZeroDivisionError, KeyError):
        return DEFAULT_STEPS_PER_FRAME
    if not math.isfinite(metres) or metres <= 0:
        return DEFAULT_STEPS_PER_FRAME
    return max(1, int(round(metres / DEFAULT_FRAMES)))


class _Camera:
    """Which steps are drawn: every ``every`` steps and the last, or the
    first step at or after each of ``times`` [s]."""

    def __init__(self, every: int | None, times=None):
        self.every = every
        self.pending = sorted(float(t) for t in times) if times is not None else None

    def wants(self, step: int, time: float, last: bool) -> bool:
        if self.pending is None:
            return step % self.every == 0 or last
        due = False
        while self.pending and time >= self.pending[0] - 1e-9:
            self.pending.pop(0)
            due = True
        return due


def _recorder(env, camera: _Camera, out: Path, bar):
    """``env`` wrapped to write a frame where ``camera`` wants one and to
    count the steps on ``bar``; its ``shots`` lists the frames written
    (:func:`play_frames`)."""
    import gymnasium as gym
    import matplotlib.image as mpimg

    class Recorder(gym.Wrapper):
        def __init__(self, inner):
            super().__init__(inner)
            self.shots: list[dict] = []
            self.steps = 0

        def _shoot(self, last: bool) -> None:
            time = _model_time(self, self.steps)
            if camera.wants(self.steps, time, last):
                frame = self.env.render()
                path = out / f"frame_{self.steps:04d}.png"
                mpimg.imsave(path, frame)
                self.shots.append(dict(step=self.steps, time=time, path=path,
                                       picture_rows=_picture_rows(self, frame)))

        def reset(self, **kwargs):
            result = super().reset(**kwargs)
            self.steps = 0
            self._shoot(False)
            return result

        def step(self, action):
            result = super().step(action)
            self.steps += 1
            bar.update()
            self._shoot(bool(result[2] or result[3]))
            return result

    return Recorder(env)


def play_frames(env, policy, seed: int, out: Path, *, every: int | None = None, times=None,
                progress: bool = True) -> dict:
    """Play one episode of ``policy`` in ``env`` (made with
    ``render_mode="rgb_array"``) from ``reset(seed=seed)``, as
    :func:`agents.rollouts.run_episode` plays the leaderboard's, writing
    frames into ``out`` every ``every`` steps (default: about
    :data:`DEFAULT_FRAMES` over a straight transit) and at the last, or at
    the model times ``times`` [s], then the whole channel at the end
    (``overview.png``, for a ship environment in its ``overview`` view).

    Returns the episode of :func:`~agents.rollouts.run_episode` (without
    its per-step series) with ``frames`` (a dict per frame: ``step``,
    ``time`` [s], ``path`` and ``picture_rows``, the rows above its panel),
    ``overview`` (the same of the frame of the whole channel) and
    ``times_missed`` (those of ``times`` after the end)."""
    import matplotlib.image as mpimg
    from tqdm.auto import tqdm

    from iceenvs.facts import env_facts

    from .rollouts import run_episode

    out.mkdir(parents=True, exist_ok=True)
    for old in out.iterdir():                 # the frames of an earlier run
        if _FRAME_FILE.match(old.name):
            old.unlink()
    if every is None and times is None:
        every = _default_every(env)
    camera = _Camera(every, times)
    total = getattr(env.spec, "max_episode_steps", None)
    with tqdm(total=total, unit="step", desc="playing", disable=not progress) as bar:
        recorder = _recorder(env, camera, out, bar)
        episode = run_episode(recorder, policy, seed, env_facts(env.spec.id).main_metric)
        bar.total = bar.n                     # the episode's length: the bar ends full
        bar.refresh()
    u = env.unwrapped
    before = getattr(u, "view", None)
    if hasattr(u, "view_box"):
        u.view = "overview"
    try:
        overview = env.render()
    finally:
        if hasattr(u, "view_box"):
            u.view = before
    overview_path = out / "overview.png"
    mpimg.imsave(overview_path, overview)
    episode = {k: v for k, v in episode.items() if k not in ("rewards", "trace")}
    episode["frames"] = recorder.shots
    episode["overview"] = dict(step=recorder.steps, time=_model_time(env, recorder.steps),
                               path=overview_path, picture_rows=overview.shape[0])
    episode["times_missed"] = list(camera.pending or [])
    return episode


def episode_summary(episode: dict) -> str:
    """``return 12.3, ice impulse per metre 14.1 kN s/m, path 1101 m,
    reached the goal, 276 steps``: the return, the ship's metrics where the
    environment logs them (:mod:`agents.metrics`' units) and the length."""
    from .metrics import metric_unit, scaled, significant

    final = episode["final"]
    parts = [f"return {significant(episode['ret'], 4)}"]
    for key in ("impulse_per_metre", "path_length"):
        if key in final:
            header, unit = metric_unit(key)[:2]
            parts.append(f"{header} {significant(scaled(key, final[key]), 3)}"
                         + (f" {unit}" if unit else ""))
    if "success" in final:
        parts.append("reached the goal" if final["success"] > 0 else "did not reach the goal")
    parts.append(f"{episode['length']} steps")
    return ", ".join(parts)


# -- the contact sheet ---------------------------------------------------------------------
def _spread(items: list, most: int) -> list:
    """At most ``most`` of ``items``, evenly spread, the first and last kept."""
    if len(items) <= most:
        return list(items)
    keep = np.unique(np.round(np.linspace(0, len(items) - 1, most)).astype(int))
    return [items[k] for k in keep]


def contact_sheet(tiles, overview, path: Path, title: str, *, width: int = SHEET_WIDTH) -> Path:
    """One PNG of the frames ``tiles`` (``[(label, picture)]``, RGB arrays,
    in order) in a grid of two columns (one for wide pictures), each under
    its label, above ``overview`` (``(label, frame)``, across the whole
    width), under ``title`` (one line or more, the first in bold); a PNG
    of 256 colours."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    from physics.scenarios.plots import save_palette_png

    dpi = 100
    pad, label_h = 10, 24
    lines = title.split("\n")
    title_h = 10 + 22 * len(lines)
    h0, w0 = tiles[0][1].shape[:2] if tiles else (1, 1)
    cols = 1 if (w0 / h0 > 2.5 or len(tiles) < 2) else 2
    rows = math.ceil(len(tiles) / cols)
    tile_w = (width - pad * (cols + 1)) / cols
    tile_h = tile_w * h0 / w0
    ov_label, ov = overview
    ov_w = width - 2 * pad
    ov_h = ov_w * ov.shape[0] / ov.shape[1]
    height = title_h + rows * (label_h + tile_h + pad) + label_h + ov_h + pad
    fig = Figure(figsize=(width / dpi, height / dpi), dpi=dpi, facecolor=SHEET_BACKGROUND)
    canvas = FigureCanvasAgg(fig)               # drawn off screen, whatever the backend

    def place(picture, label, x, y, w, h):
        """``picture`` at (x, y) [px from the top left], ``w`` × ``h``, under ``label``."""
        fig.text((x + 2) / width, 1 - (y + label_h * 0.5) / height, label, color=SHEET_TEXT,
                 fontsize=11, va="center", ha="left")
        ax = fig.add_axes((x / width, 1 - (y + label_h + h) / height, w / width, h / height))
        ax.imshow(picture, interpolation="antialiased")
        ax.set_axis_off()

    for k, line in enumerate(lines):
        fig.text(pad / width, 1 - (16 + 22 * k) / height, line, color=SHEET_TEXT,
                 fontsize=12, fontweight="bold" if k == 0 else "normal", va="center",
                 ha="left")
    for k, (label, picture) in enumerate(tiles):
        r, c = divmod(k, cols)
        place(picture, label, pad + c * (tile_w + pad), title_h + r * (label_h + tile_h + pad),
              tile_w, tile_h)
    place(ov, ov_label, pad, title_h + rows * (label_h + tile_h + pad), ov_w, ov_h)
    canvas.draw()
    # a quarter of the bytes of a full-colour PNG, no visible loss: the frames hold few colours
    save_palette_png(np.asarray(canvas.buffer_rgba())[..., :3], path, fast=True)
    return path


def _sheet(episode: dict, out: Path, title: str) -> Path:
    import matplotlib.image as mpimg

    def read(p):
        return (mpimg.imread(p)[..., :3] * 255).round().astype(np.uint8)

    tiles = [(f"step {f['step']}, t = {f['time']:.0f} s", read(f["path"])[:f["picture_rows"]])
             for f in _spread(episode["frames"], SHEET_TILES)]
    ov = episode["overview"]
    overview = (f"the whole channel at the end: step {ov['step']}, t = {ov['time']:.0f} s",
                read(ov["path"]))
    return contact_sheet(tiles, overview, out / "contact_sheet.png", title)


# -- the command ---------------------------------------------------------------------------
def build_parser(prog: str = "python -m agents.frames") -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog=prog, description=__doc__.split("\n\n")[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("policy", metavar="POLICY",
                   help="a baseline (straight, swath, lattice, ...), a policy of one's own "
                        "(module:Class or path/to/file.py:Class, ?key=value&... for its "
                        "arguments), a run of agents.train (RUN_DIR or RUN_DIR@STEPS) or a "
                        "waypoint student's run (RUN_DIR; agents.waypoints)")
    p.add_argument("--env", default=None,
                   help=f"environment id (default: a trained run's own, else {DEFAULT_ENV})")
    p.add_argument("--seed", type=int, default=10_000,
                   help="seed of the field: reset(seed=SEED) (10000, the leaderboard's field 0)")
    p.add_argument("--concentration", type=float, default=None, metavar="A",
                   help="ice concentration (the environment's argument concentration)")
    p.add_argument("--env-kwargs", nargs="*", default=[], metavar="KEY=VALUE",
                   help="gymnasium.make keywords (YAML values)")
    when = p.add_mutually_exclusive_group()
    when.add_argument("--every", type=int, default=None, metavar="K",
                      help=f"a frame every K steps, and the last (default: about "
                           f"{DEFAULT_FRAMES} frames over a ship's straight transit to the goal "
                           f"line, else every {DEFAULT_STEPS_PER_FRAME} steps)")
    when.add_argument("--times", default=None, metavar="T1,T2,...",
                      help="frames at these model times [s] (the first step at or after each)")
    p.add_argument("--view", choices=("follow", "overview"), default="follow",
                   help="a ship environment's frames: a window following the ship (follow) or "
                        "the whole channel (overview)")
    p.add_argument("--out", type=Path, default=None,
                   help="output directory (default: runs/frames/<env>_<policy>_<seed>)")
    p.add_argument("--no-progress", action="store_true", help="hide the progress bar")
    return p


def _render_modes(env_id: str) -> list:
    from iceenvs.facts import env_creator

    return list(getattr(env_creator(env_id), "metadata", {}).get("render_modes", []))


def main(argv: list[str] | None = None, prog: str = "python -m agents.frames") -> dict:
    """Run the command; returns the episode (:func:`play_frames`) with
    ``out``, ``contact_sheet`` and ``summary``."""
    parser = build_parser(prog)
    args = parser.parse_args(argv)

    from iceenvs.facts import env_spec

    from .baselines import baseline_names, check_policy_names
    from .envs import make_checked_env, parse_key_values
    from .metrics import env_name
    from .policy import is_reference
    from .rollouts import (checkpoint_files, policy_from_recipe, policy_recipe, run_agent_kwargs,
                           run_env_id, trained_argument, trained_policy)
    from .waypoint_follower import student_record

    if args.every is not None and args.every < 1:
        parser.error(f"--every must be at least 1, got {args.every}")
    times = None
    if args.times is not None:
        try:
            times = [float(t) for t in args.times.split(",") if t.strip()]
        except ValueError:
            parser.error(f"--times takes model times [s] separated by commas, got {args.times!r}")
        if not times or any(not math.isfinite(t) or t < 0 for t in times):
            parser.error(f"--times takes model times [s] >= 0, got {args.times!r}")
    try:
        env_kwargs = parse_key_values(args.env_kwargs)
    except ValueError as err:
        parser.error(str(err))
    for key, option in (("concentration", "--concentration"), ("render_mode", None),
                        ("view", "--view")):
        if key in env_kwargs:
            parser.error(f"--env-kwargs {key}: " + (f"use {option}" if option else
                                                    "the frames are drawn as rgb_array"))
    if args.concentration is not None:
        env_kwargs["concentration"] = args.concentration

    policy = args.policy
    run = None                                # a trained run: RUN_DIR[@STEPS]
    if not is_reference(policy) and _is_run(policy):
        try:
            _, run_dir, steps = trained_argument(f"run={policy}", args.env)
            if student_record(run_dir) is None:   # a waypoint student is made with its env
                checkpoint_files(run_dir, steps)                  # refuses a missing model
            run = (run_dir, steps)
        except (ValueError, FileNotFoundError) as err:
            parser.error(str(err).replace(f"--trained run={policy}", f"policy {policy}"))
        env_kwargs.update(run_agent_kwargs(run_dir))     # it acts and sees as it was trained
    env_id = args.env or (run_env_id(run[0]) if run is not None else DEFAULT_ENV)
    try:
        env_spec(env_id)
        baseline_names(env_id)      # an id without facts is refused here
    except ValueError as err:
        parser.error(f"--env {env_id}: {err}")
    if "rgb_array" not in _render_modes(env_id):
        parser.error(f"{env_id} draws no frames: its render modes are "
                     f"{_render_modes(env_id) or 'none'}, and agents.frames needs 'rgb_array'")
    if run is None:
        try:
            check_policy_names([policy], env_id,
                               also=", or a run of agents.train as RUN_DIR or RUN_DIR@STEPS")
            recipe = policy_recipe(policy)
        except ValueError as err:
            parser.error(str(err))

    try:
        env = make_checked_env(env_id, {**env_kwargs, "render_mode": "rgb_array"}, seed=args.seed)
    except ValueError as err:
        print(f"{prog}: error: {err}", file=sys.stderr)
        raise SystemExit(2) from None
    try:
        if hasattr(env.unwrapped, "view_box"):
            env.unwrapped.view = args.view
        if run is None:                        # a baseline, or a policy of one's own
            try:
                agent = policy_from_recipe(recipe, env, args.seed)
            except ValueError as err:
                parser.error(str(err))
        else:
            agent = trained_policy(run[0], env, args.seed, checkpoint=run[1])
        out = args.out or default_out(env_id, policy, args.seed, args.concentration)
        try:
            episode = play_frames(env, agent, args.seed, out, every=args.every, times=times,
                                  progress=not args.no_progress)
        finally:
            close = getattr(agent, "close", None)
            if callable(close):
                close()
        field = f"seed {args.seed}" + (f", A = {args.concentration:g}"
                                       if args.concentration is not None else "")
        summary = episode_summary(episode)
        title = f"{policy} on {env_name(env_id)}, {field}\n{summary}"
        sheet = _sheet(episode, out, title)
    finally:
        env.close()
    episode.update(out=out, contact_sheet=sheet, summary=summary)
    print(f"{policy} on {env_id} ({field}): {summary}")
    missed = episode["times_missed"]
    if missed:
        print(f"no frame at t = {', '.join(f'{t:g}' for t in missed)} s: the episode ended "
              f"at t = {episode['overview']['time']:.0f} s")
    print(f"{len(episode['frames'])} frames (frame_<step>.png), {sheet.name} and "
          f"overview.png in {out}")
    return episode


if __name__ == "__main__":
    main()
