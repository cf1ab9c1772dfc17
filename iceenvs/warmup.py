"""Compile the kernels in advance: ``python -m iceenvs.warmup``.

Numba compiles the kernels on their first use and keeps them in an on-disk
cache (see :mod:`physics._jit_cache`); the first run of an environment or
of ``make demo`` otherwise spends a minute or two compiling. This module
builds every registered environment on a small instance, resets it and
steps it with a few random actions, does the same with the native vector
environment of each that has one (training's, for several environments)
and with the costmap observation of a ship environment, then runs
``python -m physics.demo`` on a few floes and a short Hertz run on the
multi-threaded kernels, so that
later runs load everything from the cache. It prints one line per item and
the total time; an item that fails is reported and the others still run
(the exit status is then 1).

    python -m iceenvs.warmup [--steps 5] [--quiet] [--traceback]

It lives beside the environments, not in ``physics``: the physics package
never imports gymnasium, and every top-level ``physics`` module enters the
hash that names the kernel cache.
"""
from __future__ import annotations

import argparse
import contextlib
import io
import os
import sys
import tempfile
import time
import traceback
from collections.abc import Callable


class _CompileCounter:
    """Counts the compilations of the package's cached kernels (top level
    only: a kernel compiled inside another one's compilation is not counted
    again)."""

    def __init__(self):
        from numba.core import event

        from physics import _jit_cache

        self.count = 0
        depth = [0]
        counter = self

        class Listener(event.Listener):
            def on_start(self, ev):
                if depth[0] == 0 and _jit_cache.is_package_kernel(ev.data.get("dispatcher")):
                    counter.count += 1
                depth[0] += 1

            def on_end(self, ev):
                depth[0] -= 1

        self._event, self._listener = event, Listener()
        event.register("numba:compile", self._listener)

    def close(self) -> None:
        self._event.unregister("numba:compile", self._listener)


def random_steps(env, steps: int) -> None:
    """``steps`` actions sampled from ``env``'s action space, resetting
    whenever an episode ends (the environment has been reset before)."""
    for _ in range(steps):
        _, _, terminated, truncated, _ = env.step(env.action_space.sample())
        if terminated or truncated:
            env.reset()


def warm_env(env_id: str, steps: int = 5, seed: int = 0, **extra) -> str:
    """Make ``env_id`` at the small size of its facts
    (:attr:`iceenvs.facts.EnvFacts.small`: the kernels' types do not depend
    on the sizes), with the keywords ``extra`` beside them, reset it and
    take ``steps`` random actions (resetting when an episode ends). Falls
    back to the default size if the small-instance arguments are not
    accepted."""
    import gymnasium as gym

    from .facts import env_facts

    kwargs = dict(env_facts(env_id).small)
    note = ""
    try:
        env = gym.make(env_id, **kwargs, **extra)
    except TypeError:
        note = " (default size: the small-instance arguments were refused)"
        env = gym.make(env_id, **extra)
    try:
        env.action_space.seed(seed)
        env.reset(seed=seed)
        random_steps(env, steps)
    finally:
        env.close()
    return note


def warm_vector_env(env_id: str, steps: int = 5, seed: int = 0, num_envs: int = 2) -> str:
    """Make the native vector environment of ``env_id`` (its registration's
    ``vector_entry_point``, which training uses for several environments)
    with ``num_envs`` sub-environments at the small size of its facts,
    reset it and take ``steps`` random actions: its batched kernels are
    others than the single environment's."""
    import gymnasium as gym

    from .facts import env_facts

    env = gym.make_vec(env_id, num_envs=num_envs, vectorization_mode="vector_entry_point",
                       **dict(env_facts(env_id).small))
    try:
        env.action_space.seed(seed)
        env.reset(seed=seed)
        for _ in range(steps):      # the vector environment resets its sub-environments itself
            env.step(env.action_space.sample())
    finally:
        env.close()
    return ""


def warm_costmap(steps: int = 5, seed: int = 0) -> str:
    """The costmap observation (``obs_type="costmap"``, :mod:`iceenvs.costmap`)
    on the first ship environment, small, reset and stepped ``steps``
    times (:func:`warm_env`): its kernels run only for that observation."""
    from . import ENV_IDS
    from .facts import env_creator

    for env_id in ENV_IDS:
        if hasattr(env_creator(env_id), "costmap"):
            return warm_env(env_id, steps, seed, obs_type="costmap") + f" ({env_id})"
    return " (no ship environment)"


def warm_demo() -> str:
    """``python -m physics.demo`` with 30 floes pressed on the wall for 2
    model seconds and a ship transit of 2 model seconds, its output
    discarded (the kernels are the same as for the full demo; the training
    demo of ``make demo`` uses Convergence-v0, warmed above)."""
    from physics import demo

    with tempfile.TemporaryDirectory() as out, contextlib.redirect_stdout(io.StringIO()):
        try:
            demo.main(["--floes", "30", "--concentration", "0.7", "--duration", "2",
                       "--ship-duration", "2", "--no-progress", "--out", out])
        except ImportError as exc:         # matplotlib missing: only the picture fails
            return f" (no picture: {exc})"
    return ""


def warm_parallel(steps: int = 5) -> str:
    """A few steps of a small Hertz run with ``parallel=True`` (the kernels
    that the engine picks for large fields when Numba has several threads)."""
    from physics import HERMAN2013, HertzSimulation

    sim = HertzSimulation.from_preset(HERMAN2013, 300, 0.7, seed=1, velocity_std=0.01,
                                      parallel=True)
    sim.step(steps)
    sim.contacts()
    return ""


def items(steps: int = 5) -> list[tuple[str, Callable[[], str | None]]]:
    """The warm-up items, as (label, function) pairs."""
    from . import ENV_IDS

    from .facts import env_spec

    out = [(env_id, lambda env_id=env_id: warm_env(env_id, steps)) for env_id in ENV_IDS]
    out += [(f"{env_id}, native vector environment",
             lambda env_id=env_id: warm_vector_env(env_id, steps))
            for env_id in ENV_IDS if env_spec(env_id).vector_entry_point is not None]
    out.append(("costmap observation", lambda: warm_costmap(steps)))
    out.append(("physics.demo", warm_demo))
    out.append(("Hertz engine, parallel kernels", lambda: warm_parallel(steps)))
    return out


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog="python -m iceenvs.warmup",
                                description=__doc__.splitlines()[0])
    p.add_argument("--steps", type=int, default=5, help="random steps per environment (default 5)")
    p.add_argument("--quiet", action="store_true", help="print only failures")
    p.add_argument("--traceback", action="store_true", help="print the traceback of a failure")
    args = p.parse_args(argv)
    # this module says what it compiles: the one-line notice is redundant
    os.environ.setdefault("SEAICE_QUIET", "1")

    from physics import _jit_cache

    def say(text: str) -> None:
        if not args.quiet:
            print(text, flush=True)

    counter = _CompileCounter()
    where = _jit_cache.CACHE_DIR or "of Numba's default location"
    todo = items(args.steps)
    say(f"seaice-gym: filling the kernel cache {where} "
        f"(a minute or two when it is empty, a few seconds when it is not)")
    failed = 0
    t_start = time.perf_counter()
    for k, (label, fn) in enumerate(todo, 1):
        t0 = time.perf_counter()
        before = counter.count
        try:
            note = fn() or ""
        except Exception as exc:  # noqa: BLE001  (report and go on)
            failed += 1
            print(f"  [{k}/{len(todo)}] {label}: FAILED: {type(exc).__name__}: {exc}",
                  file=sys.stderr, flush=True)
            if args.traceback:
                traceback.print_exc(file=sys.stderr)
            continue
        n = counter.count - before
        what = f"compiled {n} kernel{'s' * (n != 1)}" if n else "all from the cache"
        say(f"  [{k}/{len(todo)}] {label}: {time.perf_counter() - t0:.1f} s, {what}{note}")
    total = time.perf_counter() - t_start
    counter.close()
    say(f"done in {total:.1f} s ({counter.count} kernels compiled"
        f"{f', {failed} failed' if failed else ''})")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
