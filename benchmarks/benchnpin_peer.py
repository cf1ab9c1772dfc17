"""The peer environment BenchNPIN ``ship-ice-v0``, timed the way our own
environments are: ``python -m benchmarks.benchnpin_peer``.

    python -m benchmarks.benchnpin_peer [--venv PATH] [--seconds S] [--runs R]
                                        [--seed N] [--json PATH]

What is measured
----------------
Sustained environment steps per second of BenchNPIN's ship-navigation
environment ``ship-ice-v0`` (PyPI package ``benchnpin`` 0.1.1) in its default
configuration, with the protocol of :mod:`benchmarks.bench_environments`: the
action space is seeded, the environment is reset with the seed, a warm-up of
a reset and a few random steps is left untimed (there is nothing to compile,
so no further untimed seconds), then ``runs`` consecutive runs
of at least ``seconds`` wall seconds each step it with random actions; an
episode that ends (terminated or truncated) is reset inside the run and the
reset is timed too. One thread only: ``OMP_NUM_THREADS``,
``NUMBA_NUM_THREADS``, ``MKL_NUM_THREADS`` and ``OPENBLAS_NUM_THREADS`` are 1
and OpenCV is told to use one thread; nothing is rendered
(``SDL_VIDEODRIVER=dummy``, Matplotlib's ``Agg`` back end).

Besides the rates, the result gives the configuration of the environment as
read from the environment object and its ``cfg`` (see ``benchnpin/
environments/ship_ice_nav/ship_ice_env.py`` and ``config.yaml`` beside it),
so that the two environments can be set side by side:

* the ice field: the nominal concentration (``cfg.concentration``, one of the
  five pre-generated fields 0.1 ... 0.5 shipped in the package), the floes of
  each episode (number, radii, area fraction of the map), the map size
  (``cfg.occ.map_width`` × ``cfg.occ.map_height``) and the goal line;
* the ship: a kinematic Pymunk polygon (``cfg.ship.vertices``; length and
  beam from its outline) driven at the constant ``cfg.target_speed``, the
  action being its yaw rate scaled by ``max_yaw_rate_step``;
* the time: one environment step is ``cfg.dt`` seconds of model time, made of
  ``cfg.sim.steps`` Pymunk steps of ``cfg.dt / cfg.sim.steps`` each, so
  "model time per env step" = ``cfg.dt``; each reset first lets the field
  settle for 1000 Pymunk steps (a fixed number in BenchNPIN's source);
* the observation shape and the action space, and the episode limit of the
  registration (``max_episode_steps``).

Most of a step's time goes into the observation (four 150 × 150 images
drawn from the floe polygons), less into the Pymunk steps.

The environment does not use the seed that ``reset`` is given: episode *k* of
an environment object (warm-up included) takes trial *k* mod 100 of the
shipped ice field, with the ship's start stored in that trial.

The separate virtualenv
-----------------------
BenchNPIN's declared requirements clash with this project's (it pins
``matplotlib==3.7.5``, which needs NumPy 1.x) and pull in ``torch``,
``torchvision``, ``stable-baselines3`` and ``tensorboard``, which only its
learning baselines use: nothing that ``ship-ice-v0`` imports needs them.
So BenchNPIN lives in a virtualenv of its own, made with the interpreter
that runs this module, by default in ``~/.cache/seaice-gym/benchnpin-venv``
(``--venv`` chooses another place), with these commands::

    python -m venv VENV
    VENV/bin/python -m pip install --only-binary=:all: numpy==1.26.4 \\
        matplotlib==3.7.5 pymunk==6.5.1 scipy==1.17.1 scikit-image==0.26.0 \\
        shapely==2.2.0 opencv-python-headless==4.11.0.86 pygame==2.6.1 \\
        gymnasium==1.4.0 pyyaml==6.0.4
    VENV/bin/python -m pip install --only-binary=:all: --no-deps benchnpin==0.1.1

(:data:`RUNTIME_PINS` and :data:`PACKAGE_PIN`). These are exactly the
packages the ship environment imports: NumPy, Matplotlib, Pymunk, SciPy,
scikit-image, Shapely, OpenCV (``cv2``; the headless wheel of the same
library that BenchNPIN's ``opencv-python`` names), pygame (imported by its
renderer module, never opened here), Gymnasium (the release this project
uses) and PyYAML. ``matplotlib==3.7.5`` and ``pymunk==6.5.1`` are BenchNPIN's
own pins; the others are fixed so that the measurement can be repeated.
No ``torch`` is installed. The wheel ships its ice fields (pickled
"experiments", 100 trials for each concentration), so nothing is generated.
A stamp file in the virtualenv records the pins; when it matches, the
installation is skipped.
"""
from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path
from collections.abc import Sequence

PEER = "BenchNPIN ship-ice-v0"
ENV_ID = "ship-ice-v0"
VERSION = "0.1.1"

#: BenchNPIN itself, installed without its declared dependencies
PACKAGE_PIN = f"benchnpin=={VERSION}"

#: What ``ship-ice-v0`` imports at run time, installed before BenchNPIN.
RUNTIME_PINS = (
    "numpy==1.26.4",                      # matplotlib 3.7.5 is built for NumPy 1.x
    "matplotlib==3.7.5",                  # BenchNPIN's own pin
    "pymunk==6.5.1",                      # BenchNPIN's own pin: its physics engine
    "scipy==1.17.1",
    "scikit-image==0.26.0",
    "shapely==2.2.0",
    "opencv-python-headless==4.11.0.86",  # cv2 without GUI libraries, for NumPy 1.x
    "pygame==2.6.1",                      # imported by the renderer module
    "gymnasium==1.4.0",                   # the release this project uses
    "pyyaml==6.0.4",
)

#: Options of every ``pip install``: wheels only, so nothing is compiled.
PIP_OPTIONS = ("--only-binary=:all:", "--no-input")

#: The file in the virtualenv that says the installation is complete.
STAMP_NAME = ".seaice-gym-benchnpin.json"

#: The module BenchNPIN's registration points ``ship-ice-v0`` to; importing it
#: checks that every package the environment needs is there.
CHECK_IMPORT = "benchnpin.environments.ship_ice_nav"

#: Environment of the measuring process: one thread, no window, no sound.
CHILD_ENV = {
    "OMP_NUM_THREADS": "1",
    "NUMBA_NUM_THREADS": "1",
    "MKL_NUM_THREADS": "1",
    "OPENBLAS_NUM_THREADS": "1",
    "SDL_VIDEODRIVER": "dummy",
    "SDL_AUDIODRIVER": "dummy",
    "MPLBACKEND": "Agg",
    "PYGAME_HIDE_SUPPORT_PROMPT": "1",
    "PYTHONNOUSERSITE": "1",
}

#: Untimed random steps of the warm-up, as in :mod:`benchmarks.bench_environments`.
WARMUP_STEPS = 5

#: The measuring script prints its result on one line that starts with this.
RESULT_MARKER = "BENCHNPIN-PEER-RESULT "

#: The script run inside the virtualenv, with arguments ``seconds runs seed
#: warmup_steps``. It prints raw counts; :func:`summarise` makes the figures.
MEASURE_SCRIPT = r'''
import json
import math
import platform
import sys
import time
import warnings
from importlib import metadata

seconds, runs, seed, warmup_steps = (float(sys.argv[1]), int(sys.argv[2]),
                                     int(sys.argv[3]), int(sys.argv[4]))
ENV_ID = "ship-ice-v0"
MARKER = "BENCHNPIN-PEER-RESULT "

try:                        # OpenCV keeps a thread pool of its own
    import cv2
    cv2.setNumThreads(1)
except ImportError:
    cv2 = None

import gymnasium as gym
import numpy as np

import benchnpin.environments  # noqa: F401  (registers ship-ice-v0)

warnings.simplefilter("ignore")     # the passive checker's remarks on reset()


def polygon_area(vertices):
    """Area of a simple polygon (shoelace formula)."""
    x, y = np.asarray(vertices, dtype=float).T
    return 0.5 * abs(float(np.dot(x, np.roll(y, 1)) - np.dot(y, np.roll(x, 1))))


def field(u):
    """The floes of the episode just reset: number, radii, total area."""
    floes = list(getattr(u, "obs_dicts", []))
    radii = [float(f["radius"]) for f in floes if "radius" in f]
    return dict(floes=len(getattr(u, "polygons", floes)),
                area=sum(polygon_area(f["vertices"]) for f in floes),
                radius_min=min(radii) if radii else None,
                radius_max=max(radii) if radii else None)


def version(name):
    try:
        return metadata.version(name)
    except metadata.PackageNotFoundError:
        return None


env = gym.make(ENV_ID)
u = env.unwrapped
env.action_space.seed(seed)
env.reset(seed=seed)
for _ in range(warmup_steps):                       # untimed warm-up
    _, _, term, trunc, _ = env.step(env.action_space.sample())
    if term or trunc:
        env.reset()
env.reset(seed=seed + 1)
start = [float(v) for v in getattr(u, "start", ())]

fields = [field(u)]                 # the ice of each episode of the timed runs
lengths, outcomes = [], dict(success=0, out_of_bounds=0, truncated=0)
steps, walls, reset_seconds, resets = [], [], 0.0, 0
length = 0
for _ in range(runs):
    n = 0
    t0 = time.perf_counter()
    while True:
        _, _, term, trunc, info = env.step(env.action_space.sample())
        n += 1
        length += 1
        if term or trunc:
            lengths.append(length)
            if term and info.get("trial_success"):
                outcomes["success"] += 1
            elif term:
                outcomes["out_of_bounds"] += 1      # left the map sideways
            else:
                outcomes["truncated"] += 1          # the episode limit
            r0 = time.perf_counter()
            env.reset()
            reset_seconds += time.perf_counter() - r0
            resets += 1
            length = 0
            fields.append(field(u))
        wall = time.perf_counter() - t0
        if wall >= seconds:
            break
    steps.append(n)
    walls.append(wall)

cfg = u.cfg
floes = [f["floes"] for f in fields]
radii = [r for f in fields for r in (f["radius_min"], f["radius_max"]) if r is not None]
width, height = float(cfg.occ.map_width), float(cfg.occ.map_height)
hull = np.asarray(cfg.ship.vertices, dtype=float)
space = env.action_space
config = dict(
    concentration=float(cfg.concentration),
    floes=floes[0],
    floes_per_episode=dict(min=min(floes), max=max(floes), mean=float(np.mean(floes))),
    floe_radius=[min(radii), max(radii)] if radii else None,
    ice_area_fraction=float(np.mean([f["area"] for f in fields])) / (width * height),
    ice_trials=getattr(u, "env_max_trial", None),
    map_width=width,
    map_height=height,
    goal_y=float(cfg.goal_y),
    ship_start=start,
    ship_length=float(np.ptp(hull[:, 0])),
    ship_beam=float(np.ptp(hull[:, 1])),
    ship_speed=float(cfg.target_speed),
    ship_max_yaw_rate=float(getattr(u, "max_yaw_rate_step", math.nan)),
    env_dt=float(cfg.dt),
    substeps=int(cfg.sim.steps),
    physics_dt=float(cfg.dt) / int(cfg.sim.steps),
    solver_iterations=int(cfg.sim.iterations),
    model_time_per_step=float(cfg.dt),
    settle_steps=1000,
    max_episode_steps=getattr(env.spec, "max_episode_steps", None),
    egocentric_obs=bool(cfg.egocentric_obs),
    low_dim_state=bool(cfg.low_dim_state),
    observation_shape=list(env.observation_space.shape),
    observation_dtype=str(env.observation_space.dtype),
    action_space=repr(space),
    action_shape=list(space.shape),
    action_low=np.asarray(space.low, dtype=float).ravel().tolist(),
    action_high=np.asarray(space.high, dtype=float).ravel().tolist(),
)
env.close()
result = dict(
    steps=steps, seconds=walls, resets=resets, reset_seconds=reset_seconds,
    episodes=dict(lengths=lengths, **outcomes),
    config=config,
    versions=dict(python=platform.python_version(),
                  **{name: version(name) for name in
                     ("benchnpin", "gymnasium", "pymunk", "numpy", "torch")}),
)
print(MARKER + json.dumps(result), flush=True)
'''


def default_venv() -> Path:
    """Where the virtualenv goes unless ``--venv`` says otherwise."""
    return Path.home() / ".cache" / "seaice-gym" / "benchnpin-venv"


def venv_python(venv: Path) -> Path:
    """The interpreter of the virtualenv ``venv``."""
    if os.name == "nt":
        return venv / "Scripts" / "python.exe"
    return venv / "bin" / "python"


def stamp(python_version: Sequence[int] | None = None) -> dict:
    """What the stamp file of a complete installation holds."""
    major, minor = (python_version or sys.version_info)[:2]
    return dict(pins=[*RUNTIME_PINS, PACKAGE_PIN], python=f"{major}.{minor}")


def install_commands(venv: Path, python: str | None = None) -> list[list[str]]:
    """The commands that make the virtualenv and install BenchNPIN into it."""
    py = str(venv_python(venv))
    pip = [py, "-m", "pip", "install", *PIP_OPTIONS]
    return [
        [python or sys.executable, "-m", "venv", str(venv)],
        [*pip, *RUNTIME_PINS],
        [*pip, "--no-deps", PACKAGE_PIN],
    ]


def child_environment() -> dict:
    """The environment of every process started in the virtualenv: this
    one's, less anything that would put this project's packages on its path,
    plus :data:`CHILD_ENV`."""
    env = {k: v for k, v in os.environ.items()
           if k not in ("PYTHONPATH", "PYTHONHOME", "VIRTUAL_ENV")}
    env.update(CHILD_ENV)
    return env


def _stderr_fd() -> int:
    """The file descriptor of this process's standard error, to which the
    messages of the processes started here go (their standard output is
    kept free for the result)."""
    try:
        return sys.stderr.fileno()
    except (AttributeError, OSError, ValueError):   # a stream without a descriptor
        return 2


def _log(message: str) -> None:
    print(f"[benchnpin-peer] {message}", file=sys.stderr, flush=True)


def _run(command: Sequence[str], what: str) -> None:
    """Run one installation step, its messages going to stderr; a clear
    :class:`RuntimeError` if it fails."""
    _log(f"{what}: {' '.join(command)}")
    try:
        done = subprocess.run(list(command), stdout=_stderr_fd(),
                              env=child_environment(), check=False)
    except (OSError, ValueError) as exc:
        raise RuntimeError(f"could not {what}: {' '.join(command)}: {exc}") from exc
    if done.returncode != 0:
        raise RuntimeError(f"could not {what}: the command {' '.join(command)} "
                           f"exited with status {done.returncode} (its messages are above)")


def _venv_python_version(venv: Path) -> str | None:
    """``major.minor`` of the Python a virtualenv was made with, from its
    ``pyvenv.cfg``."""
    try:
        lines = (venv / "pyvenv.cfg").read_text().splitlines()
    except OSError:
        return None
    for line in lines:
        key, _, value = line.partition("=")
        if key.strip() in ("version", "version_info"):
            return ".".join(value.strip().split(".")[:2])
    return None


def ensure_venv(venv: Path | str | None = None) -> Path:
    """Make the virtualenv with BenchNPIN in it unless its stamp file says it
    is already there with the same pins; return the virtualenv's interpreter.

    Raises :class:`RuntimeError` when the virtualenv cannot be made: the
    place is taken by something that is not a virtualenv, it was made with
    another Python, or an installation step fails.
    """
    venv = Path(venv).expanduser() if venv is not None else default_venv()
    want = stamp()
    python = venv_python(venv)
    stamp_file = venv / STAMP_NAME
    try:
        have = json.loads(stamp_file.read_text())
    except (OSError, ValueError):
        have = None
    if have == want and python.exists():
        return python

    if venv.exists():
        if not venv.is_dir() or (any(venv.iterdir()) and not (venv / "pyvenv.cfg").exists()):
            raise RuntimeError(f"cannot make the BenchNPIN virtualenv in {venv}: the place is "
                               "taken by something that is not a virtualenv; choose another "
                               "with --venv")
        made_with = _venv_python_version(venv)
        if made_with is not None and made_with != want["python"]:
            raise RuntimeError(f"the virtualenv {venv} was made with Python {made_with}, not "
                               f"{want['python']}: remove it or choose another with --venv")
    venv.parent.mkdir(parents=True, exist_ok=True)
    stamp_file.unlink(missing_ok=True)

    make, runtime, package = install_commands(venv)
    _run(make, "make the virtualenv")
    _run(runtime, "install the packages ship-ice-v0 needs")
    _run(package, f"install {PACKAGE_PIN}")
    _run([str(python), "-c", f"import {CHECK_IMPORT}"], f"import {CHECK_IMPORT}")
    stamp_file.write_text(json.dumps(want, indent=1) + "\n")
    _log(f"BenchNPIN is installed in {venv}")
    return python


def parse_output(stdout: str) -> dict:
    """The raw result of the measuring script: the JSON of its last line
    that starts with :data:`RESULT_MARKER` (the package may print other
    lines before it)."""
    for line in reversed(stdout.splitlines()):
        if line.startswith(RESULT_MARKER):
            return json.loads(line[len(RESULT_MARKER):])
    raise RuntimeError("the measurement printed no result line; its output ends with:\n"
                       + "\n".join(stdout.splitlines()[-10:]))


def summarise(raw: dict) -> dict:
    """The steps/s of each run and their mean, range and spread, with the
    rest of the raw result."""
    steps, walls = raw["steps"], raw["seconds"]
    if not steps or len(steps) != len(walls):
        raise RuntimeError(f"the measurement reported {len(steps)} runs and "
                           f"{len(walls)} durations")
    rates = [n / w for n, w in zip(steps, walls)]
    lengths = raw["episodes"]["lengths"]
    config = raw["config"]
    return dict(
        rates=rates,
        mean=statistics.fmean(rates),
        min=min(rates),
        max=max(rates),
        std=statistics.stdev(rates) if len(rates) > 1 else 0.0,
        steps=steps,
        seconds=walls,
        resets=raw["resets"],
        reset_seconds=raw["reset_seconds"],
        mean_reset_seconds=raw["reset_seconds"] / raw["resets"] if raw["resets"] else None,
        episodes=dict(raw["episodes"], completed=len(lengths),
                      mean_length=statistics.fmean(lengths) if lengths else None),
        interval=config["model_time_per_step"],
        unit="s",
        config=config,
        versions=raw["versions"],
    )


def measure(seconds: float = 20.0, runs: int = 3, seed: int = 0,
            venv: Path | str | None = None) -> dict:
    """Sustained steps/s of BenchNPIN's ``ship-ice-v0`` and its configuration,
    measured in its own virtualenv (made first if need be)."""
    if seconds <= 0 or runs < 1:
        raise ValueError("seconds must be positive and runs at least 1")
    python = ensure_venv(venv)
    command = [str(python), "-c", MEASURE_SCRIPT, repr(float(seconds)), str(int(runs)),
               str(int(seed)), str(WARMUP_STEPS)]
    # a reset or a step takes about a second at most: a generous bound
    timeout = 600.0 + 3.0 * seconds * runs
    _log(f"measuring {ENV_ID}: {runs} runs of at least {seconds:g} s, seed {seed}")
    with tempfile.TemporaryDirectory(prefix="benchnpin-peer-") as cwd:  # for stray files
        try:
            done = subprocess.run(command, stdout=subprocess.PIPE, stderr=_stderr_fd(),
                                  text=True, cwd=cwd, env=child_environment(),
                                  timeout=timeout, check=False)
        except subprocess.TimeoutExpired as exc:
            raise RuntimeError(f"the measurement took longer than {timeout:g} s") from exc
    if done.returncode != 0:
        tail = "\n".join(done.stdout.splitlines()[-10:])
        raise RuntimeError(f"the measurement in {python} exited with status "
                           f"{done.returncode} (its messages are above){': ' + tail if tail else ''}")
    result = summarise(parse_output(done.stdout))
    return dict(peer=PEER, version=result["versions"].get("benchnpin") or VERSION,
                id=ENV_ID, settings=dict(seconds=float(seconds), runs=int(runs), seed=int(seed),
                                         warmup_steps=WARMUP_STEPS, threads=1),
                **result)


def build_parser() -> argparse.ArgumentParser:
    """The command line of ``python -m benchmarks.benchnpin_peer``."""
    parser = argparse.ArgumentParser(
        prog="python -m benchmarks.benchnpin_peer",
        description=f"Sustained steps/s of the peer environment {PEER} (benchnpin {VERSION}), "
                    "in a virtualenv of its own, and its configuration.")
    parser.add_argument("--venv", type=Path, default=None,
                        help="the virtualenv to make or use (default: "
                             "~/.cache/seaice-gym/benchnpin-venv)")
    parser.add_argument("--seconds", type=float, default=20.0,
                        help="wall seconds of each timed run (default: 20)")
    parser.add_argument("--runs", type=int, default=3, help="timed runs (default: 3)")
    parser.add_argument("--seed", type=int, default=0,
                        help="seed of the action space and of reset (default: 0)")
    parser.add_argument("--json", type=Path, default=None, metavar="PATH",
                        help="also write the result to this file")
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Measure, print the result as JSON, and write it to ``--json`` if given."""
    parser = build_parser()
    args = parser.parse_args(argv)
    if args.seconds <= 0 or args.runs < 1:
        parser.error("--seconds must be positive and --runs at least 1")
    try:
        result = measure(seconds=args.seconds, runs=args.runs, seed=args.seed, venv=args.venv)
    except RuntimeError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 1
    text = json.dumps(result, indent=2)
    print(text)
    if args.json is not None:
        args.json.parent.mkdir(parents=True, exist_ok=True)
        args.json.write_text(text + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
