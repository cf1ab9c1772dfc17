"""After the set-up's warm-up (``python -m iceenvs.warmup``, which ``make
setup`` runs before ``make demo`` and ``make test``), what a first hour runs
compiles none of the project's kernels: training ShipNavigation-v1 with its
warm start on the native vector environment, evaluating the run, ranking it
on the leaderboard in worker processes, and every native vector
environment. Each command runs in a fresh process, as a user runs it; a
kernel compiled there announces itself on stderr with the one-line notice
of :mod:`physics._jit_cache`, which is what this test looks for (that the
notice appears when a kernel compiles is tested in
``tests/physics/test_jit_cache.py``)."""
import os
import subprocess
import sys
from pathlib import Path

from physics._jit_cache import compile_notice

ROOT = Path(__file__).resolve().parent.parent
V1 = "iceenvs/ShipNavigation-v1"
# the notice without the cache directory it names
NOTICE = compile_notice().split(" (")[0]

VECTOR_SNIPPET = """
import numpy as np
import iceenvs
from agents.envs import has_native_vector_env, native_vector_env
for env_id in iceenvs.ENV_IDS:
    if has_native_vector_env(env_id):
        venv = native_vector_env(env_id, 2)
        venv.seed(0)
        venv.reset()
        for _ in range(3):
            venv.step(np.array([venv.action_space.sample() for _ in range(venv.num_envs)]))
        venv.close()
        print(env_id, "stepped")
"""


def _run(args: list[str], timeout: float = 300) -> subprocess.CompletedProcess:
    env = {k: v for k, v in os.environ.items() if k != "SEAICE_QUIET"}
    env["PYTHONWARNINGS"] = "ignore"
    return subprocess.run([sys.executable, *args], cwd=ROOT, env=env, capture_output=True,
                          text=True, timeout=timeout)


def test_the_notice_names_what_is_looked_for():
    assert NOTICE == "seaice-gym: compiling the physics kernels"


def test_nothing_compiles_after_the_warmup(tmp_path):
    warm = _run(["-m", "iceenvs.warmup", "--quiet"], timeout=900)
    assert warm.returncode == 0, warm.stderr
    run = tmp_path / "run"
    commands = {
        "training": ["-m", "agents.train", "--env", V1, "--algo", "ppo", "--timesteps", "64",
                     "--n-envs", "2", "--out", str(run), "--no-progress", "--eval-freq", "0",
                     "--save-freq", "0", "--hyperparams", "n_steps=32", "batch_size=32",
                     "pretrain={teacher: swath, episodes: 1, epochs: 1}"],
        "evaluation": ["-m", "agents.evaluate", str(run), "--episodes", "1", "--baselines",
                       "straight", "--no-progress", "--out", str(tmp_path / "evaluation")],
        "leaderboard": ["-m", "agents.leaderboard", "--env", V1, "--policies",
                        "straight,swath,lattice", "--trained", f"ppo={run}", "--episodes", "2",
                        "--concentrations", "0.3", "--processes", "2", "--out",
                        str(tmp_path / "board")],
        "native vector environments": ["-c", VECTOR_SNIPPET],
    }
    for what, args in commands.items():
        done = _run(args)
        assert done.returncode == 0, f"{what}: {done.stderr[-2000:]}"
        assert NOTICE not in done.stderr, f"{what} compiled kernels after the warm-up"
    assert (tmp_path / "board" / "leaderboard.md").is_file()
    assert "stepped" in done.stdout
