"""The walk of one step of a ship task, from ``env.step`` to the kernels,
as a maintainer follows it: the modules on the call stack where the action
reaches the ship and where the step reaches the compiled Hertz step. The
Contributing page shows this walk ("One step of an environment"); a new
layer between them makes this test fail, so that the page is updated or the
layer reconsidered."""
import os
import sys
from pathlib import Path

import gymnasium as gym
import numpy as np

import iceenvs  # noqa: F401  (registers the ids)
from small_envs import SMALL

ROOT = Path(__file__).resolve().parents[2]
V1 = "iceenvs/ShipNavigation-v1"
#: the kernels' module, where the compiled step's phases run (no Python frames)
KERNELS = "physics/hertz_kernels.py"
MAX_WALK = 8


def stacks_at(env, action, targets: dict) -> dict:
    """The project modules on the call stack (outermost first) the first
    time each of ``targets`` (name → (module, function)) is entered during
    ``env.step(action)``."""
    found = {}

    def module_of(frame):
        path = frame.f_code.co_filename
        if not path.startswith(str(ROOT)) or os.sep + ".venv" + os.sep in path:
            return None
        return Path(path).relative_to(ROOT).as_posix()

    def profile(frame, event, arg):
        if event != "call":
            return
        here = (module_of(frame), frame.f_code.co_name)
        for name, target in targets.items():
            if name not in found and here == target:
                chain, f = [], frame
                while f is not None:
                    m = module_of(f)
                    if m and not m.startswith("tests/") and (not chain or chain[-1] != m):
                        chain.append(m)
                    f = f.f_back
                found[name] = chain[::-1]

    sys.setprofile(profile)
    try:
        env.step(action)
    finally:
        sys.setprofile(None)
    return found


def test_a_ship_step_walks_at_most_eight_modules_to_the_kernels():
    env = gym.make(V1, **SMALL[V1])
    env.reset(seed=0)
    env.step(np.array([0.1]))                   # compiled before it is traced
    stacks = stacks_at(env, np.array([0.1]), {
        "action": ("physics/ship.py", "command"),
        "engine": ("physics/hertz_step.py", "_run_steps"),
        "measure": ("iceenvs/ship_measures.py", "measure_ships")})
    assert stacks["action"] == ["iceenvs/base.py", "iceenvs/step.py",
                                "iceenvs/ship_navigation_v1.py", "iceenvs/ship_env.py",
                                "physics/ship.py"]
    assert stacks["engine"] == ["iceenvs/base.py", "iceenvs/step.py", "physics/hertz.py",
                                "physics/hertz_step.py"]
    assert stacks["measure"] == ["iceenvs/base.py", "iceenvs/step.py", "iceenvs/ship_env.py",
                                 "iceenvs/ship_measures.py"]
    walk = {m for key in ("action", "engine") for m in stacks[key]} | {KERNELS}
    assert len(walk) <= MAX_WALK, sorted(walk)
    env.close()
