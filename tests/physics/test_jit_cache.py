"""The kernel cache: kernels loaded from Numba's on-disk cache in a later
process must run; the cache directories of other checkouts and versions and
anything foreign under the base directory survive (only stale marked ones
are pruned); the first compilation in a process prints one line, a warm
cache nothing.

A cached kernel that calls a parallel kernel crashed every process that
loaded it when it had been compiled in a process that took the parallel
callee from the cache itself. The sequence below did that before the
parallel callees stopped being cached: one process builds a large pair
list (caching the parallel list builder), the next compiles the Hertz step
(with the list builder inside), the third loads that step from the cache.
"""
from __future__ import annotations

import os
import subprocess
import sys
import time

import pytest

BUILD_LIST = """
from physics import make_floe_field
from physics.neighbors import choose_cell_size, pair_list, radius_rank
f, b = make_floe_field(6000, concentration=0.7, alpha=1.8, mean_diameter=8.0, seed=1)
start, nbr = pair_list(f.positions, f.radii, radius_rank(f.radii), b.lx, b.ly, True, True, 0.4,
                       choose_cell_size(f.radii, b.lx, b.ly, 0.4))
print("pairs", len(nbr))
"""

HERTZ = """
from physics import HERMAN2013, HertzSimulation, make_floe_field
f, b = make_floe_field(300, concentration=0.7, alpha=1.8, mean_diameter=8.0, seed=2,
                       velocity_std=0.05)
sim = HertzSimulation(f, b, HERMAN2013.contact, None, 0.002)
sim.step(20)
print("steps", sim.n_steps)
"""


def _env(cache_dir, **extra) -> dict:
    """This process's environment with Numba's cache in ``cache_dir``, Numba
    on one thread and ``SEAICE_QUIET`` unset, then ``extra``."""
    env = {k: v for k, v in os.environ.items() if k != "SEAICE_QUIET"}
    env.update(NUMBA_CACHE_DIR=str(cache_dir), NUMBA_NUM_THREADS="1", **extra)
    return env


@pytest.fixture(scope="module")
def three_processes(tmp_path_factory):
    """(the cache's base directory, the three runs): the sequence of the
    module docstring in a fresh cache. The first and the third print what
    a user sees; the second, which compiles the Hertz step, runs with
    ``SEAICE_QUIET=1``. The tests of the one-line notice read their stderr:
    the first compiles (several kernels), the second compiles silenced, the
    third loads everything from the cache."""
    cache = tmp_path_factory.mktemp("numba-cache")
    return cache, [subprocess.run([sys.executable, "-c", script], capture_output=True,
                                  text=True, env=_env(cache, **extra), timeout=600)
                   for script, extra in ((BUILD_LIST, {}), (HERTZ, {"SEAICE_QUIET": "1"}),
                                         (HERTZ, {}))]


def test_kernels_compiled_in_one_process_run_when_loaded_in_the_next(three_processes):
    _, runs = three_processes
    for run in runs:
        assert run.returncode == 0, f"exit {run.returncode}: {run.stderr[-2000:]}"
    outputs = [run.stdout.strip().splitlines()[-1] for run in runs]
    assert outputs[0].startswith("pairs ") and int(outputs[0].split()[1]) > 0
    assert outputs[1] == outputs[2] == "steps 20"


# -- the cache directories: what configure() keeps and what it prunes ---------

def _configure_under(tmp_path, monkeypatch):
    """configure() with the base under tmp_path, leaving this process's Numba
    cache where it was."""
    import numba

    from physics import _jit_cache

    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path))
    monkeypatch.setattr(numba.config, "CACHE_DIR", numba.config.CACHE_DIR)
    return _jit_cache, _jit_cache.configure()


def test_configure_marks_its_directory_and_keeps_what_it_did_not_write(tmp_path, monkeypatch):
    base = tmp_path / "seaice-gym"
    foreign = base / "not-ours"
    foreign.mkdir(parents=True)
    (foreign / "data.bin").write_bytes(b"x")
    stray = base / "notes.txt"
    stray.write_text("keep")
    old = time.time() - 400 * 86400
    os.utime(foreign, (old, old))
    jc, target = _configure_under(tmp_path, monkeypatch)
    assert target is not None and target.parent == base
    assert (target / jc.MARKER).is_file()
    assert (foreign / "data.bin").read_bytes() == b"x"
    assert stray.read_text() == "keep"


def test_configure_keeps_other_versions_used_recently_and_prunes_stale_ones(tmp_path,
                                                                             monkeypatch):
    from physics import _jit_cache as jc

    base = tmp_path / "seaice-gym"
    recent, stale = base / "0123456789abcdef", base / "fedcba9876543210"
    for d in (recent, stale):
        d.mkdir(parents=True)
        (d / jc.MARKER).touch()
        (d / "kernel.nbi").write_bytes(b"index")
    days = 86400.0
    t_recent = time.time() - (jc.MAX_AGE_DAYS - 1) * days
    t_stale = time.time() - (jc.MAX_AGE_DAYS + 1) * days
    os.utime(recent / jc.MARKER, (t_recent, t_recent))
    os.utime(stale / jc.MARKER, (t_stale, t_stale))
    _, target = _configure_under(tmp_path, monkeypatch)
    assert (recent / "kernel.nbi").is_file()
    assert not stale.exists()
    # the directory in use is renewed on every use, however old its marker
    os.utime(target / jc.MARKER, (t_stale, t_stale))
    _configure_under(tmp_path, monkeypatch)
    assert (target / jc.MARKER).stat().st_mtime > time.time() - days


# -- the line printed before the first compilation ---------------------------

def test_first_compilation_prints_one_line_and_a_warm_cache_none(three_processes):
    from physics._jit_cache import compile_notice

    cache, (first, quiet, warm) = three_processes
    assert first.returncode == quiet.returncode == warm.returncode == 0, first.stderr[-2000:]
    lines = [ln for ln in first.stderr.splitlines() if ln.startswith("seaice-gym: compiling")]
    assert len(lines) == 1, first.stderr                    # several kernels, one line
    target = cache / "seaice-gym"
    assert lines[0] == compile_notice(next(p for p in target.iterdir() if p.is_dir()))
    assert warm.stderr == ""                                 # loaded from the cache
    assert quiet.stderr == ""                                # compiled, and silenced
