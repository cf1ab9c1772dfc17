"""What the benchmark suites share: the machine, fresh processes, timing
rounds, the two-thread ceilings, the progress bar and the JSON records.

Fresh processes
    :func:`spawn_call` runs a plain function in a process started with
    :mod:`multiprocessing`'s ``"spawn"`` context (nothing inherited from the
    parent's memory, its own Numba thread pool of a given size, optionally
    pinned to one core, optionally importing ``physics`` and ``iceenvs``
    from another source tree) and returns what the function returns.
Timing
    :func:`interleaved_rounds` makes several configurations take turns, so
    that on a shared machine whose speed drifts every configuration sees
    the same good and bad moments. :func:`machine_scaling` times two control
    loops on one and on all threads: the most that two threads can give on
    the machine at all.
Records
    Each suite writes one JSON record::

        {"suite", "title", "description", "command", "machine", "date",
         "wall_seconds", "tables": [{"title", "columns", "rows", "notes"}],
         "data"}

    ``description`` and ``notes`` are Markdown; ``rows`` hold strings and
    numbers; ``data`` holds the raw figures. :func:`render_markdown` renders
    a record and :func:`load_records` reads those of a directory.

This module imports neither ``physics`` nor ``iceenvs``.
"""
from __future__ import annotations

import argparse
import datetime
import importlib
import json
import math
import multiprocessing
import os
import platform
import resource
import shlex
import sys
import time
import traceback
from pathlib import Path
from collections.abc import Callable, Sequence

import numba
import numpy as np

from . import SUITES, suite_module

#: timed rounds per process; within a round the configurations take turns
REPEATS = 5
#: fresh processes per case (host noise only slows a run down)
PROCESSES = 3
#: the source checkout the suites come with (they are not installed), whatever
#: the working directory
ROOT = Path(__file__).resolve().parent.parent
#: where a suite writes its record by default: runs/benchmarks of the checkout
DEFAULT_DIR = ROOT / "runs" / "benchmarks"
#: the records the documentation shows: docs/benchmarks of the checkout,
#: written only when asked for (``--docs``, ``make records``)
DOCS_DIR = ROOT / "docs" / "benchmarks"
#: where the prepared floe fields are kept: .bench_cache of the checkout
CACHE_DIR = ROOT / ".bench_cache"
#: keys of every record, in the order they are written
RECORD_KEYS = ("suite", "title", "description", "command", "commit", "machine", "date",
               "wall_seconds", "tables", "data")
#: keys that records written before them lack (``commit``: the source commit)
LATER_KEYS = ("commit",)
#: keys of every table of a record
TABLE_KEYS = ("title", "columns", "rows", "notes")
#: keys of a record's machine description
MACHINE_KEYS = ("cpu", "logical_cpus", "numba_threads", "python", "numpy", "numba", "platform")


# ---------------------------------------------------------------------------
# the machine
# ---------------------------------------------------------------------------

def cpu_model() -> str | None:
    """The CPU model from ``/proc/cpuinfo`` (Linux), else what
    :mod:`platform` knows, else ``None``."""
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                key, _, value = line.partition(":")
                if key.strip() in ("model name", "Hardware", "cpu model") and value.strip():
                    return value.strip()
    except OSError:
        pass
    return platform.processor() or None


def machine_info(numba_threads: int | None = None) -> dict:
    """The machine and the versions a record was measured with.
    ``numba_threads`` is the size of the thread pool the timed code ran
    with (default: this process's)."""
    threads = numba.config.NUMBA_NUM_THREADS if numba_threads is None else int(numba_threads)
    return dict(cpu=cpu_model() or platform.machine(), logical_cpus=os.cpu_count(),
                numba_threads=threads, python=platform.python_version(),
                numpy=np.__version__, numba=numba.__version__, platform=platform.platform())


def peak_rss() -> int:
    """Peak resident memory of this process so far [bytes] (Linux)."""
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024


def utc_now() -> str:
    """The present time, ISO 8601 in UTC to the second."""
    return datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds")


# ---------------------------------------------------------------------------
# fresh processes
# ---------------------------------------------------------------------------

def _target_name(fn: Callable) -> str:
    """``module:qualname`` of a module-level function, with the real module
    name of a module run as ``python -m``."""
    if not callable(fn) or "<locals>" in getattr(fn, "__qualname__", "<locals>"):
        raise TypeError(f"a child process runs a module-level function, got {fn!r}")
    module = fn.__module__
    if module == "__main__":
        spec = getattr(sys.modules["__main__"], "__spec__", None)
        if spec is None:
            raise TypeError(f"{fn.__qualname__} is defined in a script, not in a module")
        module = spec.name
    return f"{module}:{fn.__qualname__}"


def _loaded_from() -> dict:
    """Where the project's packages loaded in this process come from."""
    return {name: getattr(sys.modules[name], "__file__", None)
            for name in ("physics", "iceenvs") if name in sys.modules}


def _child_entry(conn, target: str, args: tuple, kwargs: dict, cpu: int | None,
                 source: str | None) -> None:
    """Body of a child of :func:`spawn_call`: put ``source`` first on the
    module path, pin to ``cpu``, call ``target`` and send back
    ``("ok", result, loaded_from)`` or ``("error", traceback, loaded_from)``."""
    try:
        if source is not None:
            sys.path.insert(0, source)
            os.environ["PYTHONPATH"] = os.pathsep.join(
                [source] + [p for p in os.environ.get("PYTHONPATH", "").split(os.pathsep) if p])
        if cpu is not None:
            os.sched_setaffinity(0, {cpu})
        module, _, name = target.partition(":")
        fn = importlib.import_module(module)
        for part in name.split("."):
            fn = getattr(fn, part)
        conn.send(("ok", fn(*args, **kwargs), _loaded_from()))
    except BaseException:  # noqa: BLE001  (everything goes back to the parent)
        conn.send(("error", traceback.format_exc(), _loaded_from()))
    finally:
        conn.close()


def module_file(name: str) -> str | None:
    """Import module ``name`` and return its ``__file__`` (a check, in a
    child of :func:`spawn_call`, of where a package resolves)."""
    return getattr(importlib.import_module(name), "__file__", None)


class ChildError(RuntimeError):
    """A benchmark child process failed; the message ends with its traceback."""


class Child:
    """A function running in a fresh spawned process (see :func:`start`).
    ``daemon=False`` lets the function start processes of its own (it is
    then not stopped with its parent, only by :meth:`kill`)."""

    def __init__(self, fn: Callable, args: tuple = (), kwargs: dict | None = None, *,
                 threads: int | None = None, cpu: int | None = None,
                 source: str | os.PathLike | None = None, daemon: bool = True):
        if threads is not None and (int(threads) != threads or threads < 1):
            raise ValueError(f"threads must be a positive whole number, got {threads!r}")
        ctx = multiprocessing.get_context("spawn")
        self._recv, send = ctx.Pipe(duplex=False)
        self.target = _target_name(fn)
        self._process = ctx.Process(
            target=_child_entry, daemon=daemon,
            args=(send, self.target, tuple(args), dict(kwargs or {}), cpu,
                  None if source is None else str(source)))
        saved = os.environ.get("NUMBA_NUM_THREADS")
        try:            # the child reads its environment when it starts
            if threads is not None:
                os.environ["NUMBA_NUM_THREADS"] = str(int(threads))
            self._process.start()
        finally:
            if saved is None:
                os.environ.pop("NUMBA_NUM_THREADS", None)
            else:
                os.environ["NUMBA_NUM_THREADS"] = saved
        send.close()
        #: ``__file__`` of ``physics`` and ``iceenvs`` in the child, once it has returned
        self.loaded_from: dict = {}

    def result(self):
        """Wait for the child and return what its function returned.

        Raises
        ------
        ChildError
            If the function raised, or the process died without an answer.
        """
        try:
            status, value, self.loaded_from = self._recv.recv()
        except EOFError:
            self._process.join()
            raise ChildError(f"{self.target} died (exit code {self._process.exitcode})") from None
        finally:
            self._recv.close()
        self._process.join()
        if status != "ok":
            raise ChildError(f"{self.target} failed in its process:\n{value}")
        return value

    def kill(self) -> None:
        """End the child if it still runs."""
        if self._process.is_alive():
            self._process.kill()
        self._process.join()


def spawn_call(fn: Callable, *args, threads: int | None = None, cpu: int | None = None,
               source: str | os.PathLike | None = None, daemon: bool = True, **kwargs):
    """``fn(*args, **kwargs)`` in a fresh process, and its result.

    Parameters
    ----------
    fn : callable
        A module-level function of an importable module; its arguments and
        result must be picklable.
    threads : int, optional
        Size of the child's Numba thread pool (``NUMBA_NUM_THREADS``);
        default: that of this process's environment.
    cpu : int, optional
        Core the child is pinned to.
    source : path, optional
        A source tree put first on the child's module path, so that
        ``import physics`` and ``import iceenvs`` resolve there (the
        benchmark's own modules must not have imported them before).
    daemon : bool
        ``False`` for a function that starts processes of its own.

    Raises
    ------
    ChildError
        If ``fn`` raised in the child.
    """
    return Child(fn, args, kwargs, threads=threads, cpu=cpu, source=source,
                 daemon=daemon).result()


def spawn_together(fn: Callable, arg_lists: Sequence[tuple], *, threads: int | None = None,
                   cpus: Sequence[int | None] | None = None) -> list:
    """Start ``fn(*args)`` for every ``args`` of ``arg_lists`` at once, each
    in its own process (pinned to the matching core of ``cpus``), and return
    their results in order."""
    cpus = [None] * len(arg_lists) if cpus is None else list(cpus)
    if len(cpus) != len(arg_lists):
        raise ValueError("cpus must give one core per call")
    children = [Child(fn, tuple(a), threads=threads, cpu=c) for a, c in zip(arg_lists, cpus)]
    try:
        return [c.result() for c in children]
    finally:
        for c in children:
            c.kill()


# ---------------------------------------------------------------------------
# options
# ---------------------------------------------------------------------------

def pick_names(text: str | None, known: Sequence[str], what: str,
               groups: dict[str, Sequence[str]] | None = None) -> list[str]:
    """The names of a comma-separated option (``"a,b"``: names of ``known``
    or of ``groups``, each standing for several) in the order of ``known``;
    ``None``: all of them.

    Raises
    ------
    ValueError
        If a name is unknown ("unknown ``what``(s) ..."), or none is given.
    """
    if text is None:
        return list(known)
    groups = groups or {}
    asked = [w.strip() for w in str(text).split(",") if w.strip()]
    unknown = [w for w in asked if w not in known and w not in groups]
    if unknown or not asked:
        also = f", or the groups {', '.join(groups)}" if groups else ""
        raise ValueError(f"unknown {what}(s) {', '.join(unknown) or '(none)'}; known: "
                         f"{', '.join(known)}{also}")
    picked = {k for w in asked for k in groups.get(w, (w,))}
    return [k for k in known if k in picked]


# ---------------------------------------------------------------------------
# timing
# ---------------------------------------------------------------------------

def interleaved_rounds(runs: Sequence[Callable[[], float]], rounds: int = REPEATS) -> list[list]:
    """Call every function of ``runs`` once per round, in turn, for
    ``rounds`` rounds; ``out[k][r]`` is what ``runs[k]`` returned in round
    ``r``. On a shared machine whose speed drifts over seconds, the turns
    put every configuration through the same moments, and two results of
    one round compare like with like."""
    out = [[] for _ in runs]
    for _ in range(rounds):
        for k, run in enumerate(runs):
            out[k].append(run())
    return out


def best_time(fn: Callable[[], object], repeats: int = 5) -> float:
    """Best wall time of ``repeats`` calls of ``fn`` after one warm-up call [s]."""
    fn()
    best = math.inf
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t0)
    return best


@numba.njit(parallel=True, cache=True)
def _control_loop(reps):
    """Scalar, branchy arithmetic with no memory traffic: how well the
    machine itself runs two threads at once."""
    out = np.zeros(64)
    for c in numba.prange(64):
        t = 0.0
        for i in range(reps):
            x = (i * 2654435761 + c) % 1000 * 0.001
            if x > 0.5:
                t += x * x
            else:
                t -= x
        out[c] = t
    return out


STREAM_PASSES = 6   # updates per floe and step: a step costs about what a Hertz step does


@numba.njit(parallel=True, cache=True)
def _stream_loop(state, steps):
    """A kick-drift-like pass over an (N, 8) floe-state array per step, in
    64 chunks: how well the machine runs two threads on a streaming kernel
    whose data, like the Hertz engine's at N = 20000, sits in the caches."""
    n = state.shape[0]
    for _ in range(steps):
        for c in numba.prange(64):
            for i in range(c * n // 64, (c + 1) * n // 64):
                for _ in range(STREAM_PASSES):
                    state[i, 2] += 1e-6 * state[i, 4]
                    state[i, 3] += 1e-6 * state[i, 5]
                    state[i, 0] += 1e-3 * state[i, 2]
                    state[i, 1] += 1e-3 * state[i, 3]
                    state[i, 6] = state[i, 2] * state[i, 2] + state[i, 3] * state[i, 3]


def control_child(kind: str = "scalar", scale: float = 1.0) -> dict:
    """Time a control loop on one thread and on all threads, taking turns
    (:func:`interleaved_rounds`); return ``{"ratios": [...]}``, the
    all-threads / one-thread speed-up of every round. ``scale`` shortens
    the loops (1: the full benchmark)."""
    if kind == "stream":
        state = np.random.default_rng(0).random((20000, 8))
        _stream_loop(state, 2)
        steps = max(1, int(2000 * scale))
        run = lambda: _stream_loop(state, steps)  # noqa: E731
    elif kind == "scalar":
        _control_loop(10)
        reps = max(1, int(500000 * scale))
        run = lambda: _control_loop(reps)  # noqa: E731
    else:
        raise ValueError(f"kind must be 'scalar' or 'stream', got {kind!r}")

    def timed(threads):
        def go():
            numba.set_num_threads(threads)
            t0 = time.perf_counter()
            run()
            return time.perf_counter() - t0
        return go

    one, every = interleaved_rounds([timed(1), timed(numba.config.NUMBA_NUM_THREADS)])
    return dict(ratios=[a / b for a, b in zip(one, every)])


def machine_scaling(threads: int, kind: str = "scalar", processes: int = PROCESSES,
                    scale: float = 1.0) -> list[float]:
    """Speed-ups of a control kernel on ``threads`` threads over one thread,
    one per round of :func:`control_child` in ``processes`` fresh
    processes: ``kind="scalar"``, arithmetic with no memory traffic (the
    ceiling for compute-bound kernels), or ``"stream"``, a pass over cached
    floe-state arrays (the ceiling for the per-floe passes)."""
    return [x for _ in range(processes)
            for x in spawn_call(control_child, kind, scale, threads=threads)["ratios"]]


# ---------------------------------------------------------------------------
# progress
# ---------------------------------------------------------------------------

class Progress:
    """A tqdm bar on stderr counting the measurements of a suite, and
    :meth:`log` for lines on stdout that do not break it. ``quiet``: no
    bar and no lines."""

    def __init__(self, total: int, desc: str, quiet: bool = False, unit: str = "run"):
        from tqdm.auto import tqdm

        self.quiet = quiet
        self._tqdm = tqdm
        self._bar = tqdm(total=total, desc=desc, unit=unit, disable=quiet, leave=False,
                         dynamic_ncols=True, file=sys.stderr)

    def log(self, message: str) -> None:
        """Print a line above the bar (nothing when quiet)."""
        if not self.quiet:
            self._tqdm.write(message, file=sys.stdout)
            sys.stdout.flush()

    def advance(self, k: int = 1) -> None:
        """Count ``k`` more measurements done."""
        self._bar.update(k)

    def close(self) -> None:
        self._bar.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


# ---------------------------------------------------------------------------
# records
# ---------------------------------------------------------------------------

def in_checkout(path: Path) -> str:
    """A default path of the checkout as the help texts show it (not this
    machine's absolute path), e.g. ``docs/benchmarks of the checkout``."""
    return f"{path.relative_to(ROOT).as_posix()} of the checkout"


def suite_parser(suite: str, description: str,
                 prog: str | None = None) -> argparse.ArgumentParser:
    """The command-line parser of ``python -m benchmarks.bench_<suite>`` (shown as
    ``prog`` when given, e.g. ``seaice bench <suite>``), with ``--quiet`` and
    the options of :func:`add_common_options`."""
    parser = argparse.ArgumentParser(prog=prog or f"python -m {suite_module(suite)}",
                                     description=description,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--quiet", action="store_true", help="print only the result")
    add_common_options(parser, suite)
    return parser


def add_common_options(parser: argparse.ArgumentParser, suite: str) -> None:
    """``--quick``, ``--json PATH``, ``--docs`` (the record the
    documentation shows, :data:`DOCS_DIR`) and ``--no-json``."""
    parser.add_argument("--quick", action="store_true",
                        help="a small run that only checks that everything works (its figures "
                             "mean nothing)")
    out = parser.add_mutually_exclusive_group()
    out.add_argument("--json", type=Path, default=DEFAULT_DIR / f"{suite}.json",
                     help=f"where to write the record (default "
                          f"{in_checkout(DEFAULT_DIR / f'{suite}.json')})")
    out.add_argument("--docs", dest="json", action="store_const",
                     const=DOCS_DIR / f"{suite}.json",
                     help=f"write the record that the documentation shows, "
                          f"{in_checkout(DOCS_DIR / f'{suite}.json')} (as make records does)")
    out.add_argument("--no-json", action="store_true", help="write no record")


def command_line(suite: str, argv: Sequence[str]) -> str:
    """The command that ran a suite, as the ``seaice`` command spells it."""
    return shlex.join(["seaice", "bench", suite, *map(str, argv)])


def parse(parser: argparse.ArgumentParser, argv) -> tuple[argparse.Namespace, list[str]]:
    """Parse ``argv`` (default: ``sys.argv[1:]``); returns the options and
    the arguments as a list."""
    argv = sys.argv[1:] if argv is None else [str(a) for a in argv]
    return parser.parse_args(argv), argv


def settings(args: argparse.Namespace, defaults: dict, quick: dict,
             keys: Sequence[str]) -> dict:
    """A suite's settings: ``defaults``, updated by ``quick`` under
    ``--quick``, then by each option of ``keys`` given on the command line."""
    st = dict(defaults)
    if args.quick:
        st.update(quick)
    st.update({key: getattr(args, key) for key in keys if getattr(args, key) is not None})
    return st


def table(title: str, columns: Sequence[str], rows: Sequence[Sequence], notes: str = "") -> dict:
    """One table of a record.

    Raises
    ------
    ValueError
        If a row does not have one cell per column.
    """
    columns = [str(c) for c in columns]
    rows = [list(r) for r in rows]
    for r in rows:
        if len(r) != len(columns):
            raise ValueError(f"table {title!r}: a row of {len(r)} cells for {len(columns)} "
                             f"columns: {r!r}")
    return dict(title=str(title), columns=columns, rows=rows, notes=str(notes))


def _plain(value):
    """``value`` with NumPy scalars and arrays made plain Python, and
    non-finite floats made ``None`` (JSON has no NaN)."""
    if isinstance(value, dict):
        return {str(k): _plain(v) for k, v in value.items()}
    if isinstance(value, (list, tuple, np.ndarray)):
        return [_plain(v) for v in value]
    if isinstance(value, np.generic):
        value = value.item()
    if isinstance(value, float) and not math.isfinite(value):
        return None
    if isinstance(value, Path):
        return str(value)
    return value


def make_record(suite: str, title: str, description: str, command: str, tables: Sequence[dict],
                data: dict, wall_seconds: float, machine: dict | None = None,
                date: str | None = None) -> dict:
    """A record of the documented layout (see the module docstring), with
    the source commit it was measured with (:mod:`physics.provenance`)."""
    from physics.provenance import source_commit

    return _plain(dict(suite=suite, title=title, description=description.strip(),
                       command=command, commit=source_commit(),
                       machine=machine or machine_info(), date=date or utc_now(),
                       wall_seconds=None if wall_seconds is None else float(wall_seconds),
                       tables=list(tables), data=data))


def validate_record(record: dict) -> None:
    """Check the layout of a record.

    Raises
    ------
    TypeError
        If ``record`` is not a dict.
    ValueError
        If a key is missing or a table is not rectangular.
    """
    if not isinstance(record, dict):
        raise TypeError(f"a record is a dict, got {type(record).__name__}")
    missing = [k for k in RECORD_KEYS if k not in record and k not in LATER_KEYS]
    if missing:
        raise ValueError(f"record misses {', '.join(missing)}")
    missing = [k for k in MACHINE_KEYS if k not in record["machine"]]
    if missing:
        raise ValueError(f"record's machine misses {', '.join(missing)}")
    for t in record["tables"]:
        missing = [k for k in TABLE_KEYS if k not in t]
        if missing:
            raise ValueError(f"a table misses {', '.join(missing)}")
        table(t["title"], t["columns"], t["rows"], t["notes"])


def write_record(record: dict, path: str | os.PathLike) -> Path:
    """Write ``record`` as JSON to ``path`` (folders made as needed)."""
    validate_record(record)
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(_plain(record), indent=2, ensure_ascii=False, allow_nan=False)
                    + "\n", encoding="utf-8")
    return path


def load_records(directory: str | os.PathLike = DOCS_DIR) -> list[dict]:
    """The records of ``directory`` (files ``<suite>.json``, then a suite's
    further records ``<suite>-<name>.json`` in the order of their names), in
    the order of :data:`benchmarks.SUITES`; suites without a file are left
    out."""
    directory = Path(directory)
    out = []
    for suite in SUITES:
        paths = [directory / f"{suite}.json", *sorted(directory.glob(f"{suite}-*.json"))]
        for path in paths:
            if path.is_file():
                out.append(json.loads(path.read_text(encoding="utf-8")))
    return out


def format_number(value) -> str:
    """A table cell: whole numbers as they are, rates of 10⁵ and more and
    small values in three significant digits with an exponent, the rest
    to three significant digits (no exponent from 100 up)."""
    if value is None:
        return "–"
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return str(value)
    if isinstance(value, int):
        return str(value)
    if not math.isfinite(value):
        return "–"
    if 100 <= abs(value) < 1e5:
        return f"{value:.0f}"
    return f"{value:.3g}"


def _cell(value) -> str:
    """A table cell as Markdown: :func:`format_number`, bars escaped, on one line."""
    # imported here: a child of the harness may import physics from another tree
    from physics.markdown import table_cell

    return table_cell(format_number(value))


def render_table(t: dict, heading: str | None = "###") -> str:
    """One table as Markdown: its title (as a heading of level
    ``heading``, or a plain line if ``None``), the table and its notes."""
    lines = [f"{heading} {t['title']}" if heading else t["title"], "",
             "| " + " | ".join(t["columns"]) + " |", "|" + "---|" * len(t["columns"])]
    lines += ["| " + " | ".join(_cell(c) for c in row) + " |" for row in t["rows"]]
    if t.get("notes"):
        lines += ["", t["notes"]]
    return "\n".join(lines)


def machine_line(record: dict) -> str:
    """How, where and when a record was measured, in one line."""
    m = record["machine"]
    versions = ", ".join(f"{k} {m[k]}" for k in ("python", "numpy", "numba") if m.get(k))
    commit = f"; commit {record['commit']}" if record.get("commit") else ""
    return (f"Command: `{record['command']}`{commit}; machine: {m.get('cpu') or '?'}, "
            f"{m.get('logical_cpus')} logical CPUs, {m.get('numba_threads')} Numba "
            f"thread{'s' * (m.get('numba_threads') != 1)}, {versions}, {m.get('platform')}; "
            f"date: {record['date']}"
            + (f"; wall time {record['wall_seconds']:.0f} s." if record.get("wall_seconds")
               is not None else "."))


def render_markdown(record: dict) -> str:
    """A record as MyST/Markdown: the title as a level-2 heading, the
    description, each table (a level-3 heading, the table, its notes) and
    a line with the command, the machine and the date."""
    validate_record(record)
    parts = [f"## {record['title']}", record["description"]]
    parts += [render_table(t) for t in record["tables"]]
    parts.append(machine_line(record))
    return "\n\n".join(p for p in parts if p) + "\n"


def finish(args: argparse.Namespace, record: dict, show: bool = True) -> dict:
    """Print the rendered record (if ``show``) and write it where the
    options say (``--json``, ``--no-json``)."""
    if show:
        print()
        print(render_markdown(record))
    if not args.no_json:
        path = write_record(record, args.json)
        print(f"record: {path}")
    return record
