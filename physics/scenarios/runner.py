"""Run a scenario: its cases × ensemble members in parallel processes, with a
progress bar, checkpoints, a resumable run directory, NetCDF output, figures
and a summary table.

A run directory holds::

    run.yaml        what was run: scenario file, parameters, seeds, command, versions
    jobs/           one NetCDF per finished (case, member); checkpoints of unfinished ones
    results.nc      all runs together (dimensions case, member, sample, ...)
    figures/*.png   the scenario's figures
    summary.md      the summary table printed at the end

Ensemble member m of every case gets the seed ``SeedSequence(seed).spawn(K)[m]``
(the same random floe field across the cases of a sweep), so a run is
reproduced exactly by its seed; a run resumed from checkpoints continues the
very trajectories it was interrupted in.
"""
from __future__ import annotations

import datetime as _dt
import os
import platform
import shlex
import shutil
import signal
import sys
import threading
import time
from dataclasses import dataclass
from queue import Empty
from pathlib import Path
from types import SimpleNamespace

import numpy as np

from .config import ScenarioConfig, bundled_configs, dump_yaml, load_config, parse_config
from .dask_pool import check_options as check_dask
from .dask_pool import describe as describe_dask
from .dask_pool import run_on_dask
from ..markdown import table_row
from .engines import check_engine
from .experiment import get_experiment
from .jobs import init_worker, job_paths, run_job
from .recorder import atomic_write, checkpoint_fraction

RUN_FILE = "run.yaml"
RESULTS_FILE = "results.nc"


def find_config(scenario) -> ScenarioConfig:
    """A scenario by name (a shipped file) or by the path of a YAML file."""
    if isinstance(scenario, ScenarioConfig):
        return scenario
    text = str(scenario)
    if text.endswith((".yaml", ".yml")) or os.sep in text:
        cfg = load_config(text)
    else:
        files = bundled_configs()
        if text not in files:
            raise ValueError(f"unknown scenario {text!r}; valid scenarios: "
                             f"{', '.join(files)} (or the path of a scenario file)")
        cfg = load_config(files[text])
    get_experiment(cfg.name)           # the file must name a known experiment
    return cfg


def member_seeds(seed: int, ensemble: int) -> list[int]:
    """Seeds of the ensemble members, derived reproducibly from ``seed``."""
    children = np.random.SeedSequence(int(seed)).spawn(int(ensemble))
    return [int(c.generate_state(1, dtype=np.uint64)[0] >> np.uint64(1)) for c in children]


def versions() -> dict[str, str]:
    import numba
    import xarray

    from .. import __version__
    return {"seaice-gym": __version__, "python": platform.python_version(),
            "numpy": np.__version__, "numba": numba.__version__, "xarray": xarray.__version__,
            "platform": platform.platform()}


@dataclass
class RunResult:
    """What :func:`run_scenario` made."""

    directory: Path
    dataset: Path
    figures: list[Path]
    summary: list[tuple[str, str, str]]
    wall_time: float


# ---------------------------------------------------------------------------
# the run
# ---------------------------------------------------------------------------

def _prepare_directory(out: Path, force: bool, resume: bool) -> None:
    if resume:
        if not (out / RUN_FILE).exists():
            raise FileNotFoundError(f"{out} is not a run directory (no {RUN_FILE}); nothing to "
                                    f"resume")
        return
    if out.exists() and any(out.iterdir()):
        if not force:
            raise FileExistsError(f"output directory {out} exists; pass --force to overwrite it "
                                  f"or --resume to continue the run in it")
        shutil.rmtree(out)
    (out / "jobs").mkdir(parents=True, exist_ok=True)


def run_scenario(scenario, *, overrides: dict | None = None, floes: int | None = None,
                 seed: int = 0, ensemble: int = 1, quick: bool = False, out=None,
                 force: bool = False, workers: int | None = None,
                 checkpoint_every: float = 60.0, progress: bool = True, plots: bool = True,
                 command: str | None = None, log=print, dask: dict | None = None,
                 engine: str = "numba", mpi_ranks: int | None = None) -> RunResult:
    """Run ``scenario`` (a name or a YAML path) and write its run directory.

    ``overrides`` are parameter values (checked against the file's ranges);
    ``floes`` is a shortcut for the ``floes`` parameter. ``out`` defaults to
    ``runs/NAME`` (``runs/NAME-quick`` with ``quick``); an existing directory
    is only replaced with ``force``. See :func:`resume_run` to continue an
    interrupted run. ``engine`` is "numba" (our engines) or "lammps"
    (:mod:`physics.scenarios.engines`, the Herman 2013 scenarios); with
    ``mpi_ranks`` N each LAMMPS run goes to ``mpiexec -n N``
    (:mod:`physics.scenarios.lammps_job`). ``dask`` runs the jobs on Dask instead of local
    processes: ``{"local": N}`` (a LocalCluster of N workers) or
    ``{"scheduler": ADDRESS}`` (see :mod:`physics.scenarios.dask_pool`).
    """
    cfg = find_config(scenario)
    overrides = dict(overrides or {})
    if floes is not None:
        if "floes" not in cfg.params:
            raise ValueError(f"scenario {cfg.name!r} has no floes parameter (--floes); valid "
                             f"parameters: {', '.join(cfg.params)}")
        overrides["floes"] = floes
    if int(ensemble) < 1:
        raise ValueError(f"ensemble must be a positive number of members, got {ensemble}")
    if int(seed) < 0:
        raise ValueError(f"seed must be a non-negative integer, got {seed}")
    dask = check_dask(dask)
    check_engine(engine, get_experiment(cfg.name))
    if mpi_ranks is not None:
        from .lammps_job import check_ranks

        check_ranks(mpi_ranks)
        if engine != "lammps":
            raise ValueError("--mpi runs the LAMMPS engine on several ranks; add --engine lammps "
                             "(the numba engine uses threads on one machine)")
    _check_engine_and_dask(engine, dask)
    params = cfg.resolve(overrides, quick=quick)
    if not get_experiment(cfg.name).cases(params):
        raise ValueError(f"these parameters give scenario {cfg.name!r} nothing to run (an empty "
                         f"list of cases)")
    out = Path(out) if out is not None else Path("runs") / (cfg.name + ("-quick" if quick else ""))
    _prepare_directory(out, force, resume=False)
    run_info = dict(scenario=cfg.name, title=cfg.title, reproduces=cfg.reproduces,
                    quick=bool(quick), seed=int(seed), ensemble=int(ensemble),
                    member_seeds=member_seeds(seed, ensemble), parameters=params,
                    overrides=overrides, command=command or "", config=cfg.data,
                    engine=engine, mpi_ranks=int(mpi_ranks or 1),
                    created=_dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds"),
                    versions=versions())
    atomic_write(out / RUN_FILE, lambda tmp: Path(tmp).write_text(dump_yaml(run_info)))
    return _execute(out, run_info, workers, checkpoint_every, progress, plots, log, dask)


def resume_run(out, *, workers: int | None = None, checkpoint_every: float = 60.0,
               progress: bool = True, plots: bool = True, log=print,
               dask: dict | None = None) -> RunResult:
    """Continue the run in directory ``out``: finished simulations are kept,
    interrupted ones restart from their last checkpoint, the rest start
    (``dask`` as for :func:`run_scenario`)."""
    import yaml

    dask = check_dask(dask)
    out = Path(out)
    _prepare_directory(out, False, resume=True)
    run_info = yaml.safe_load((out / RUN_FILE).read_text())
    engine = run_info.get("engine", "numba")
    check_engine(engine)
    _check_engine_and_dask(engine, dask)
    return _execute(out, run_info, workers, checkpoint_every, progress, plots, log, dask)


def _check_engine_and_dask(engine: str, dask) -> None:
    """LAMMPS jobs run under mpiexec: refuse them on Dask."""
    if engine == "lammps" and dask:
        raise ValueError("the LAMMPS engine runs its jobs under mpiexec, not on Dask; drop "
                         "--scheduler/--dask-local or use the numba engine")


def _execute(out: Path, info: dict, workers, checkpoint_every, progress, plots, log,
             dask=None) -> RunResult:
    t0 = time.perf_counter()
    cfg = parse_config(info["config"])
    exp = get_experiment(cfg.name)
    params = info["parameters"]
    cases = exp.cases(params)
    seeds = info["member_seeds"]
    jobs = []
    for c, case in enumerate(cases):
        for m, s in enumerate(seeds):
            nc_path, _ = job_paths(out, c, m)
            jobs.append(dict(c=c, m=m, case=case, seed=s, done=nc_path.exists(),
                             cost=exp.workload(params, case)))
    todo = sorted((j for j in jobs if not j["done"]), key=lambda j: -j["cost"])
    n_cpu = os.cpu_count() or 1
    workers = min(len(todo), n_cpu) if workers is None else max(1, min(int(workers), len(todo) or 1))
    log(f"{cfg.name}: {len(cases)} case(s) x {len(seeds)} member(s) = {len(jobs)} run(s)"
        + (f", {len(jobs) - len(todo)} already finished" if len(todo) < len(jobs) else "")
        + (f", one after the other on LAMMPS with {info.get('mpi_ranks', 1)} MPI rank(s)"
           if info.get("engine", "numba") == "lammps" else describe_dask(dask) if dask
           else f", {workers} in parallel" if workers > 1 else "")
        + f" -> {out}")
    if todo:
        _run_jobs(out, info, todo, workers, checkpoint_every, progress, dask, log)
    ds = combine(out, info, cases, exp)
    atomic_write(out / RESULTS_FILE, lambda tmp: ds.to_netcdf(tmp, engine="h5netcdf"))
    figures = []
    if plots:
        figures = make_figures(out, ds, exp, params)
    rows = exp.summarise(ds, params)
    wall = time.perf_counter() - t0
    table = format_summary(cfg, rows, wall, out, ds.attrs.get("notes", ""),
                           quick=bool(info.get("quick")))
    (out / "summary.md").write_text(table + "\n")
    log(table)
    return RunResult(out, out / RESULTS_FILE, figures, rows, wall)


def _run_jobs(out: Path, info: dict, todo: list, workers: int, checkpoint_every, progress,
              dask=None, log=print):
    """Run the unfinished jobs, ``workers`` at a time (or on Dask), with one
    progress bar."""
    from tqdm.auto import tqdm

    fractions = {k: checkpoint_fraction(job_paths(out, j["c"], j["m"])[1])
                 for k, j in enumerate(todo)}
    bar = tqdm(total=len(todo), unit="run", desc=info["scenario"], disable=not progress,
               dynamic_ncols=True, bar_format="{l_bar}{bar}| {n:.2f}/{total} runs "
                                               "[{elapsed}<{remaining}]")
    lock = threading.Lock()

    def update(k, f):
        with lock:
            fractions[k] = max(fractions[k], f)
            bar.update(sum(fractions.values()) - bar.n)    # tqdm throttles the redraws
    update(0, fractions[0])
    args = [(info["config"], info["parameters"], j["case"], j["seed"], str(out), j["c"],
             j["m"], checkpoint_every, k) for k, j in enumerate(todo)]
    in_main = threading.current_thread() is threading.main_thread()
    stop = []      # the signal that asked an in-process job to stop

    def on_signal(signum, frame):
        # An exception raised here while a compiled kernel runs in this
        # process would surface as a SystemError from inside Numba, so an
        # in-process job stops at its next progress report (at most one
        # output interval later); a second signal stops at once.
        if workers == 1 and not dask and not stop:
            stop.append(signum)
            return
        raise KeyboardInterrupt

    def in_process_update(k, f):
        update(k, f)
        if stop:
            raise KeyboardInterrupt
    previous = {}
    if in_main:
        for sig in (signal.SIGTERM, signal.SIGINT):
            if signal.getsignal(sig) is not signal.SIG_IGN:    # nohup'ed: leave it ignored
                previous[sig] = signal.signal(sig, on_signal)
    try:
        if info.get("engine", "numba") == "lammps":
            from .lammps_job import run_lammps_jobs

            run_lammps_jobs(args, int(info.get("mpi_ranks", 1)), update)
        elif dask:
            run_on_dask(args, update, dask, log)
        elif workers == 1:
            for k, a in enumerate(args):
                run_job(*a, on_progress=lambda f, k=k: in_process_update(k, f))
                update(k, 1.0)
        else:
            _run_pool(args, workers, update)
    except KeyboardInterrupt:
        bar.close()
        print(f"\ninterrupted: finished runs and checkpoints are kept in {out}; continue with\n"
              f"  ice-scenarios run --resume {shlex.quote(str(out))}", file=sys.stderr)
        raise
    finally:
        for sig, handler in previous.items():
            signal.signal(sig, handler)
        bar.close()


def _run_pool(args, workers, update):
    import multiprocessing as mp
    from concurrent.futures import ProcessPoolExecutor, as_completed

    ctx = mp.get_context("spawn")     # fresh interpreters: no Numba thread pool is forked
    queue = ctx.Queue()
    stop = threading.Event()

    def pump():
        while not stop.is_set():
            try:
                k, f = queue.get(timeout=0.2)
            except Empty:
                continue
            update(k, f)
    reader = threading.Thread(target=pump, daemon=True)
    reader.start()
    pool = ProcessPoolExecutor(max_workers=workers, mp_context=ctx, initializer=init_worker,
                               initargs=(queue, 1))
    try:
        futures = {pool.submit(run_job, *a): a[-1] for a in args}
        for fut in as_completed(futures):
            fut.result()
            update(futures[fut], 1.0)
    except BaseException:
        for p in list(getattr(pool, "_processes", {}).values()):
            p.terminate()
        pool.shutdown(wait=False, cancel_futures=True)
        raise
    finally:
        stop.set()
        reader.join(timeout=1.0)
    pool.shutdown()


# ---------------------------------------------------------------------------
# results
# ---------------------------------------------------------------------------

def combine(out: Path, info: dict, cases: list[dict], exp):
    """All job datasets of the run directory as one dataset with dimensions
    ``case`` and ``member`` in front."""
    import xarray as xr

    fill = {"contact_i": -1, "contact_j": -1, "floe_frozen": 0}
    per_case = []
    notes = []
    for c in range(len(cases)):
        members = []
        for m in range(len(info["member_seeds"])):
            path, _ = job_paths(out, c, m)
            with xr.open_dataset(path, engine="h5netcdf") as d:
                members.append(d.load())
            if members[-1].attrs.get("notes"):
                notes.append(f"case {c} {cases[c]}, member {m}: {members[-1].attrs['notes']}")
        per_case.append(xr.concat(members, "member", join="outer", fill_value=fill,
                                  combine_attrs="drop"))
    ds = xr.concat(per_case, "case", join="outer", fill_value=fill, combine_attrs="drop")
    ds.coords["member"] = ("member", np.arange(len(info["member_seeds"])))
    ds["member_seed"] = ("member", np.array([str(s) for s in info["member_seeds"]], dtype=object))
    ds.coords["case"] = ("case", np.arange(len(cases)))
    for key in dict.fromkeys(k for case in cases for k in case):
        name = key if key not in ds.data_vars else f"{key}_case"   # a recorded variable keeps its name
        ds.coords[name] = ("case", np.array([case.get(key, np.nan) for case in cases]))
    for key, (units, description) in exp.variables.items():
        if key in ds:
            ds[key].attrs.update(units=units, long_name=description)
    params = info["parameters"]
    ds.attrs.update(
        scenario=info["scenario"], title=info["title"], reproduces=info["reproduces"],
        quick=int(info["quick"]), seed=int(info["seed"]), ensemble=int(info["ensemble"]),
        command=info.get("command", ""), created=info["created"],
        engine=info.get("engine", "numba"), mpi_ranks=int(info.get("mpi_ranks", 1)),
        parameters=dump_yaml(params), versions=dump_yaml(info["versions"]),
        notes="\n".join(notes), Conventions="CF-1.8")
    for key, value in params.items():
        ds.attrs[f"param_{key}"] = (int(value) if isinstance(value, bool)
                                    else np.asarray(value) if isinstance(value, list) else value)
    return ds


def make_figures(out: Path, ds, exp, params) -> list[Path]:
    import matplotlib
    matplotlib.use("Agg")
    fig_dir = out / "figures"
    fig_dir.mkdir(exist_ok=True)
    return [Path(p) for p in exp.plot(ds, params, fig_dir)]


def load_run(directory):
    """(directory, run.yaml contents, experiment, results) of a finished
    run directory; a clear error if it holds no results."""
    import xarray as xr
    import yaml

    out = Path(directory)
    if not (out / RESULTS_FILE).exists():
        raise FileNotFoundError(f"{out} holds no {RESULTS_FILE}: not a finished run directory"
                                + (" (resume it with ice-scenarios run --resume)"
                                   if (out / RUN_FILE).exists() else ""))
    info = yaml.safe_load((out / RUN_FILE).read_text())
    exp = get_experiment(info["scenario"])
    with xr.open_dataset(out / RESULTS_FILE, engine="h5netcdf") as ds:
        ds = ds.load()
    return out, info, exp, ds


def summarise_run(directory) -> str:
    """The summary table of a finished run directory, computed afresh from
    its results (the analysis may be newer than the run); summary.md, with
    the run's wall time, is left as it is."""
    out, info, exp, ds = load_run(directory)
    # the header from the run's own record: its scenario file may be a copy
    cfg = SimpleNamespace(name=info["scenario"], title=info.get("title", ""),
                          reproduces=info.get("reproduces", ""))
    rows = exp.summarise(ds, info["parameters"])
    return format_summary(cfg, rows, None, out, ds.attrs.get("notes", ""),
                          quick=bool(info.get("quick")))


#: the line a summary of a ``--quick`` run carries under its heading
QUICK_NOTE = ("This is the `--quick` form, a smaller and faster set-up than the paper's "
              "(`ice-scenarios show NAME` lists both): it shows the scenario at work, and its "
              "numbers are not expected to match the paper's column. The full runs are "
              "compared with the papers on the documentation's Reproduction page.")


def format_summary(cfg: ScenarioConfig, rows, wall: float | None, out: Path,
                   notes: str = "", quick: bool = False) -> str:
    when = "" if wall is None else f" Wall time {_hms(wall)}."
    lines = [f"## {cfg.name}: {cfg.title}", "",
             f"Reproduces {cfg.reproduces}. Output: {out}.{when}", ""]
    if quick:
        lines += [QUICK_NOTE, ""]
    if rows:
        lines += ["| quantity | this run | paper |", "|---|---|---|"]
        lines += [table_row(row) for row in rows]
    if notes:
        lines += ["", "Notes:"] + [f"- {n}" for n in notes.splitlines()]
    return "\n".join(lines)


def _hms(seconds: float) -> str:
    s = int(round(seconds))
    return f"{s // 3600}:{s % 3600 // 60:02d}:{s % 60:02d}" if s >= 3600 else \
        f"{s // 60}:{s % 60:02d}" if s >= 60 else f"{seconds:.1f} s"


def plot_run(directory) -> list[Path]:
    """(Re)make the figures of a finished run directory."""
    out, info, exp, ds = load_run(directory)
    return make_figures(out, ds, exp, info["parameters"])
