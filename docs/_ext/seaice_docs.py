"""Pages of the documentation that are generated at build time.

Everything here is written under ``docs/_generated/`` (not kept in the
repository) when the builder starts:

* ``environments/<name>.md`` — one page per registered environment id, made
  from the class docstring (its specification), with a frame rendered by
  ``env.render()`` after a seeded reset and a few seeded steps
  (``frames/<name>.png``, reused if present);
* ``figures/scaling.png`` — the speed-up against Numba threads of each
  workload of the scaling benchmark's record, shown with its tables;
* ``figures/where_time_goes.png`` — the shares of a ShipNavigation-v1
  substep and of PPO training on it, from the where_time_goes record;
* ``figures/free_drift.png`` — the equivalence test of the ship's steps, per
  step, concentration, policy and metric beside the control, from the
  free_drift record;
* ``api/<module>.md`` — one autodoc page per public module;
* ``include/`` — parts of hand-written pages: the lists of those pages in
  registry order (``environments_toc.md``, ``api_toc.md``), the tables of the
  benchmark records of ``docs/benchmarks/*.json`` (``benchmarks.md``), the
  ``--help`` of the console commands (``cli.md``), the parameters of every
  bundled scenario file (``scenario_parameters.md``), the cross-check
  report of ``docs/crosscheck/`` (``crosscheck_report.md``) and the common
  observation entries of the floe environments (``observations.md``).

A file is rewritten only when its text changes, so incremental builds stay
incremental.
"""
from __future__ import annotations

import importlib
import math
import os
import pkgutil
import re
import subprocess
import sys
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

from sphinx.util import logging

log = logging.getLogger(__name__)

#: packages whose public modules get an API page
API_PACKAGES = ("physics", "iceenvs", "agents", "seaice_gym")
#: seed, number of steps and action seed of the rendered frames
FRAME_SEED = 0
FRAME_STEPS = 5

_ROLE = re.compile(r":(\w+(?::\w+)?):`")


def write_if_changed(path: Path, text: str) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    if not path.is_file() or path.read_text(encoding="utf-8") != text:
        path.write_text(text, encoding="utf-8")


def save_png_if_changed(fig, path: Path) -> None:
    """A Matplotlib figure as a PNG at ``path`` (no software tag, so the
    bytes depend on the figure alone), rewritten only when it changes."""
    import io

    buffer = io.BytesIO()
    fig.savefig(buffer, format="png", dpi=110, metadata={"Software": None})
    data = buffer.getvalue()
    path.parent.mkdir(parents=True, exist_ok=True)
    if not path.is_file() or path.read_bytes() != data:
        path.write_bytes(data)


def with_record_figure(text: str, record: dict, out: Path, draw, alt: str, caption: str,
                       name: str | None = None) -> str:
    """The rendered record ``text`` with the figure that ``draw(record,
    path)`` writes to ``figures/<name>.png`` of ``out`` (``name``: the
    record's suite unless given) between its tables and its last line
    (command, machine, date); ``text`` as it is when ``draw`` returns False
    (nothing to draw)."""
    name = f"{name or record['suite']}.png"
    if not draw(record, out / "figures" / name):
        return text
    body, _, last = text.strip().rpartition("\n\n")
    figure = "\n".join([f"```{{figure}} /{out.name}/figures/{name}", f":alt: {alt}",
                        ":width: 100%", "", caption, "```"])
    return f"{body}\n\n{figure}\n\n{last}\n"


def myst_roles(text: str) -> str:
    """Docstring roles (``:func:`x```) in MyST syntax (``{func}`x```)."""
    return _ROLE.sub(r"{\1}`", text)


# ---------------------------------------------------------------------------
# Environments


def registered_environments() -> list[tuple[str, object]]:
    """(id, EnvSpec) of every environment ``iceenvs`` registers, in its order."""
    import gymnasium as gym
    import iceenvs

    return [(env_id, gym.spec(env_id)) for env_id in iceenvs.ENV_IDS]


def environment_class(spec):
    module, _, name = spec.entry_point.partition(":")
    return getattr(importlib.import_module(module), name)


def render_frame(env_id: str, path: Path) -> None:
    """A frame of ``env_id`` after ``reset(seed=FRAME_SEED)`` and a few seeded steps."""
    import gymnasium as gym
    from matplotlib.image import imsave

    env = gym.make(env_id, render_mode="rgb_array")
    try:
        env.reset(seed=FRAME_SEED)
        env.action_space.seed(FRAME_SEED)
        for _ in range(FRAME_STEPS):
            env.step(env.action_space.sample())
        frame = env.render()
    finally:
        env.close()
    path.parent.mkdir(parents=True, exist_ok=True)
    imsave(path, frame)


def docstring_markdown(doc: str) -> str:
    """A Markdown docstring without its indentation. Lines that start at the
    margin (tables pasted into an f-string docstring) do not count towards
    the common indentation."""
    lines = doc.expandtabs().splitlines()
    indents = [len(l) - len(l.lstrip()) for l in lines[1:] if l.strip()]
    margin = min((i for i in indents if i > 0), default=0)
    body = [l[margin:] if l[:margin].isspace() else l for l in lines[1:]]
    return "\n".join([lines[0].strip()] + body).strip()


def environment_page(env_id: str, spec, frame: str) -> str:
    cls = environment_class(spec)
    summary, _, body = docstring_markdown(cls.__doc__ or "").partition("\n\n")
    summary = " ".join(summary.split())
    module = cls.__module__
    source = module.replace(".", "/") + ".py"
    reward = getattr(cls, "reward_fn", None)
    reward = getattr(reward, "__func__", reward)
    lines = [
        f"# {env_id}", "",
        summary.replace("\n", " "), "",
        f"```{{image}} {frame}", f":alt: a frame of {env_id}", ":width: 480px", "```", "",
        f"*A frame from `env.render()` after `reset(seed={FRAME_SEED})` and {FRAME_STEPS} "
        "random steps.*", "",
        "| | |", "|---|---|",
        f"| id | `{env_id}` |",
        f"| class | {{class}}`{module}.{cls.__name__}` |",
        f"| source | `{source}` |",
        f"| episode length | {spec.max_episode_steps} steps (`max_episode_steps`) |",
    ]
    if reward is not None and getattr(reward, "__module__", None):
        lines.append(f"| reward | {{func}}`{reward.__module__}.{reward.__name__}` "
                     f"(`{reward.__module__.replace('.', '/')}.py`) |")
    facts = cls.facts
    lines += [f"| main metric | `{facts.main_metric}` |",
              f"| baselines | {_baselines(facts)} |",
              f"| small instance (tests, warm-up) | {_kwargs(facts.small)} |",
              f"| reference agent | {_reference_agent(env_id)} |"]
    lines += ["", "```python", "import gymnasium as gym",
              "import iceenvs  # noqa: F401  (registers the ids)", "",
              f'env = gym.make("{env_id}", render_mode="rgb_array")',
              "obs, info = env.reset(seed=0)", "```", "",
              myst_roles(body), ""]
    return "\n".join(lines)


def _reference_agent(env_id: str) -> str:
    """A link to the id's row of the reference agents' benchmark, or the
    page when the id has no reference agent yet."""
    from agents.reference import reference_dir

    name = env_id.split("/")[-1]
    if (reference_dir(env_id) / "model.zip").is_file():
        return (f"`docs/agents/reference/{name}` ([its benchmark row and baselines]"
                f"(/reference-agents.md#{name.lower()}))")
    return "none yet ({doc}`/reference-agents`)"


def _baselines(facts) -> str:
    """The generic baselines and the environment's own controllers."""
    own = ", ".join(f"`{name}` ({{class}}`~{cls.__module__}.{cls.__name__}`)"
                    for name, cls in facts.controllers.items())
    return "`random`, `zero`, `constant`" + (f", {own}" if own else "")


def _kwargs(kwargs) -> str:
    return ", ".join(f"`{k}={v!r}`" for k, v in kwargs.items()) or "the defaults"


def environments_table(envs) -> str:
    """One row per registered id, from its facts and its registration."""
    rows = ["| id | task | actions | main metric | steps | native vector env |",
            "|---|---|---|---|---|---|"]
    for env_id, spec in envs:
        cls = environment_class(spec)
        name = env_id.split("/")[-1]
        actions = ", ".join(f"`{a}`" for a in getattr(cls, "action_names", ()))
        vector = "yes" if spec.vector_entry_point is not None else "no"
        rows.append(f"| {{doc}}`{env_id} </_generated/environments/{name}>` | "
                    f"{cls.facts.summary} | {actions} | `{cls.facts.main_metric}` | "
                    f"{spec.max_episode_steps} | {vector} |")
    return "\n".join(rows + [""])


def generate_environments(out: Path) -> None:
    envs = registered_environments()
    write_if_changed(out / "include" / "environments_table.md", environments_table(envs))
    toc = ["```{toctree}", ":maxdepth: 1", ""]
    for env_id, spec in envs:
        name = env_id.split("/")[-1]
        frame = out / "frames" / f"{name}.png"
        if not frame.is_file():
            log.info(f"rendering a frame of {env_id}")
            render_frame(env_id, frame)
        write_if_changed(out / "environments" / f"{name}.md",
                         environment_page(env_id, spec, f"../frames/{name}.png"))
        toc.append(f"/_generated/environments/{name}")
    write_if_changed(out / "include" / "environments_toc.md", "\n".join(toc + ["```", ""]))


def observation_table() -> str:
    from iceenvs.observations import FLOE_FEATURES, feature_table

    return feature_table(FLOE_FEATURES)


# ---------------------------------------------------------------------------
# Benchmarks


def _cell(value) -> str:
    if isinstance(value, float):
        return f"{value:.3g}"
    from physics.markdown import table_cell

    return table_cell(value)


def scaling_figure(record: dict, path: Path) -> bool:
    """The speed-up over one thread against Numba threads of each workload
    of a scaling record (``benchmarks.bench_scaling``), one panel each, beside the
    ceiling loop and the ideal line, as a PNG at ``path`` (rewritten only
    when it changes). Returns ``False``, writing nothing, when the record
    has no timed workload beside the ceiling loop."""
    import textwrap

    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure
    from matplotlib.ticker import FuncFormatter

    results = [r for r in record["data"]["results"] if "failed" not in r]
    ceiling = next((r for r in results if r["workload"] == "ceiling"), None)
    panels = [r for r in results if r["workload"] != "ceiling"]
    if not panels:
        return False
    threads = record["data"]["threads"]
    cols = min(3, len(panels))
    rows = -(-len(panels) // cols)
    fig = Figure(figsize=(3.4 * cols, 3.0 * rows), layout="constrained")
    FigureCanvasAgg(fig)
    axes = fig.subplots(rows, cols, squeeze=False).ravel()
    for ax, res in zip(axes, panels):
        ax.plot(threads, threads, ":", color="0.4", label="ideal", zorder=3)
        if ceiling is not None:
            ax.plot([r["threads"] for r in ceiling["rows"]],
                    [r["speedup"] for r in ceiling["rows"]], "--o", color="black", ms=3,
                    label="ceiling loop")
        x = [r["threads"] for r in res["rows"]]
        y = [r["speedup"] for r in res["rows"]]
        low = [max(0.0, s - min(r["paired"])) for s, r in zip(y, res["rows"])]
        high = [max(0.0, max(r["paired"]) - s) for s, r in zip(y, res["rows"])]
        ax.errorbar(x, y, yerr=[low, high], fmt="-o", color="tab:blue", ms=4, capsize=2,
                    label="this workload")
        ax.set_xscale("log", base=2)
        ax.set_yscale("log", base=2)
        ax.set_xticks(threads, [str(k) for k in threads])
        ax.yaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
        ax.minorticks_off()
        ax.set_title("\n".join(textwrap.wrap(res["label"], 40)), fontsize=8)
        ax.set_xlabel("Numba threads", fontsize=8)
        ax.set_ylabel("speed-up over 1 thread", fontsize=8)
        ax.tick_params(labelsize=7)
        ax.grid(True, which="major", alpha=0.3)
    for ax in axes[len(panels):]:
        ax.set_visible(False)
    axes[0].legend(fontsize=7, loc="upper left")
    save_png_if_changed(fig, path)
    return True


#: colours of the where_time_goes figure's parts, in order
_SHARE_COLOURS = ("tab:blue", "tab:orange", "tab:green", "tab:red", "tab:purple", "tab:brown",
                  "tab:pink", "tab:gray")


def where_time_goes_figure(record: dict, path: Path) -> bool:
    """Horizontal stacked bars of the shares of a where_time_goes record
    (``benchmarks.bench_where_time_goes``): a late engine substep under the exact
    step (its kick–drift pass, live-pair loop and the rest) and under the
    fast step (classification, closed form, list rebuilds, the engaged
    floes' steps), and PPO training in each configuration (engine,
    environments' Python, adapter, VecNormalize, policy, buffer, update,
    rest), as a PNG at ``path`` (rewritten only when it changes). Returns
    ``False``, writing nothing, when the record has neither."""

    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    from benchmarks.bench_where_time_goes import SHARE_LABELS, SHARES

    data = record["data"]
    bars = []
    if data.get("substep"):
        summary = data["substep"]["summary"]
        s = summary["shares"]
        bars.append(("engine substep, exact step", [("kick–drift pass", s["kick_drift"]),
                                                    ("live-pair loop", s["live_pairs"]),
                                                    ("rest of the substep", s["rest"])]))
        if summary.get("fast"):
            f = summary["fast"]["shares"]
            bars.append(("engine substep, fast step (the default)",
                         [("classification of the windows", f["classify"]),
                          ("closed form of the free floes", f["sync"]),
                          ("Verlet list rebuilds", f["rebuild"]),
                          ("steps of the engaged floes", f["steps"])]))
    for configuration, r in (data.get("ppo") or {}).items():
        s = r["one"]["shares"]
        bars.append((f"PPO training, {configuration} configuration, one thread",
                     [(SHARE_LABELS[k].split(" (")[0], s[k]) for k in SHARES]))
    if not bars:
        return False
    fig = Figure(figsize=(7.5, 1.0 + 1.6 * len(bars)), layout="constrained")
    FigureCanvasAgg(fig)
    axes = fig.subplots(len(bars), 1, squeeze=False).ravel()
    for ax, (name, parts) in zip(axes, bars):
        left = 0.0
        for (label, share), colour in zip(parts, _SHARE_COLOURS):
            share = max(0.0, float(share or 0.0))
            ax.barh([0], [100 * share], left=[100 * left], color=colour, edgecolor="white",
                    label=label)
            if share >= 0.06:
                ax.text(100 * (left + share / 2), 0, f"{100 * share:.0f} %", ha="center",
                        va="center", fontsize=7, color="white")
            left += share
        ax.set_xlim(0, 100)
        ax.set_yticks([])
        ax.set_title(name, fontsize=9, loc="left")
        ax.set_xlabel("share of the wall time [%]", fontsize=8)
        ax.tick_params(labelsize=7)
        ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0), frameon=False)
    save_png_if_changed(fig, path)
    return True


#: markers of the free_drift figure's metrics
_METRIC_MARKERS = ("o", "s", "D", "v")


def free_drift_figure(record: dict, path: Path) -> bool:
    """The equivalence test of a free_drift record (``benchmarks.bench_free_drift``),
    one panel per step compared with the exact one: for each concentration,
    policy and metric, the centre of the per-field differences relative to
    the exact mean with its interval (the statistic the control chose),
    beside the control's (grey), and the band of the margin. A row is
    equivalent when its bar lies inside the band. A PNG at ``path``
    (rewritten only when it changes). Returns ``False``, writing nothing,
    when the record has no statistics."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    from benchmarks.bench_free_drift import CONTROL, METRICS

    stats = record["data"].get("statistics")
    if not stats or not stats.get("rows"):
        return False
    rows = stats["rows"]
    margin = 100 * record["data"]["margin"]
    steps = list(record["data"]["settings"]["variants"])
    groups = list(dict.fromkeys((r["concentration"], r["policy"]) for r in rows))
    keys = [key for key, *_ in METRICS]
    labels = {key: label for key, label, *_ in METRICS}
    fig = Figure(figsize=(10.0, 2.6 * len(steps) + 0.6), layout="constrained")
    FigureCanvasAgg(fig)
    axes = fig.subplots(len(steps), 1, sharex=True, squeeze=False)[:, 0]
    width = 0.8 / len(keys)
    limit = 4.0 * margin
    for ax, step in zip(axes, steps):
        ax.axhspan(-margin, margin, color="0.9", zorder=0, label=f"±{margin:g} % margin")
        ax.axhline(0.0, color="0.4", lw=0.8)
        for k, key in enumerate(keys):
            for who, colour, shift in ((CONTROL, "0.55", -0.25), (step, f"C{k}", 0.25)):
                xs, ys, lo, hi = [], [], [], []
                for g, group in enumerate(groups):
                    r = next(r for r in rows if (r["concentration"], r["policy"]) == group
                             and r["metric"] == key)
                    iv = r["runs"][who][r["statistic"] or "mean"]
                    if not all(v is not None and math.isfinite(v) for v in iv):
                        continue
                    c, a, b = (100 * v for v in iv)
                    xs.append(g - 0.4 + width * (k + 0.5 + shift))
                    ys.append(max(-limit, min(limit, c)))
                    lo.append(max(0.0, min(limit, c) - max(-limit, a)))
                    hi.append(max(0.0, min(limit, b) - max(-limit, c)))
                ax.errorbar(xs, ys, yerr=[lo, hi], fmt=_METRIC_MARKERS[k % 4], ms=3.5,
                            capsize=1.5, lw=0.9, color=colour,
                            mfc="none" if who == CONTROL else colour,
                            label=(labels[key] if who != CONTROL else
                                   ("control (nudged), each metric" if k == 0 else None)))
        ax.set_ylim(-limit, limit)
        ax.set_ylabel(f"({step} − exact) / exact [%]", fontsize=8)
        ax.tick_params(axis="y", labelsize=7)
        ax.grid(True, axis="y", alpha=0.3)
        ax.set_title(f"{step} against the exact step, beside the control", fontsize=9)
    axes[0].legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0), frameon=False)
    axes[-1].set_xticks(range(len(groups)), [f"{a:g}\n{name}" for a, name in groups],
                        fontsize=7)
    axes[-1].set_xlim(-0.6, len(groups) - 0.4)
    save_png_if_changed(fig, path)
    return True


def generate_benchmarks(out: Path, directory: Path) -> None:
    from benchmarks.harness import load_records, render_markdown

    records = load_records(directory)
    parts = []
    for r in records:
        text = render_markdown(r).strip() + "\n"
        if r["suite"] == "scaling":
            text = with_record_figure(
                text, r, out, scaling_figure,
                "speed-up over one thread against Numba threads, each workload beside the "
                "ceiling loop and the ideal line",
                "Speed-up over one thread against Numba threads, best over best, with the range "
                "of the same-round ratios as bars: each workload (solid) beside the "
                "memory-bound ceiling loop (dashed) and ideal scaling (dotted).")
        elif r["suite"] == "where_time_goes":
            text = with_record_figure(
                text, r, out, where_time_goes_figure,
                "shares of the wall time of a ShipNavigation-v1 engine substep under each step "
                "and of PPO training on it",
                "Shares of the wall time: a late ShipNavigation-v1 engine substep under the "
                "exact and under the fast step, and PPO training on its native vector "
                "environment in each configuration, from the tables above.")
        elif r["suite"] == "free_drift":
            from benchmarks.bench_free_drift import ENV_ID

            settings = r["data"]["settings"]
            env = settings.get("env", ENV_ID)
            name = "free_drift" if env == ENV_ID else f"free_drift-{env.split('/')[1]}"
            if settings.get("statistic") == "control":
                name += "-pilot"
            text = with_record_figure(
                text, r, out, free_drift_figure,
                "the equivalence test: each step's relative difference from the exact step "
                "with its interval, beside the control's, and the margin",
                "The equivalence test, one panel per step: for each concentration and policy "
                "(below the axis) and each metric (colour), the centre of the per-field "
                "differences from the exact step relative to the exact mean, with its 90 % "
                "interval; grey hollow markers beside each: the control, the exact step "
                "with every floe nudged by a rounding error, which shows what chaos alone "
                "does to the same fields. A row is equivalent when its bar lies in the grey "
                "band of the margin; values beyond four times the margin are drawn at the "
                "edge.",
                name=name)
        parts.append(text)
    if not parts:
        parts = ["No benchmark records yet: `make records` writes them to `docs/benchmarks/`.\n"]
    write_if_changed(out / "include" / "benchmarks.md", "\n".join(parts))


# ---------------------------------------------------------------------------
# Cross-check report


def table_safe(text: str) -> str:
    """Markdown tables whose last cells hold ``|`` (an absolute value), with
    those bars escaped: a row keeps the header's number of columns."""
    out, columns = [], None
    for line in text.splitlines():
        if line.startswith("|"):
            cells = line.strip().strip("|").split("|")
            if columns is None:
                columns = len(cells)
            elif len(cells) > columns:
                cells = cells[:columns - 1] + ["\\|".join(cells[columns - 1:])]
            line = "|" + "|".join(cells) + "|"
        else:
            columns = None
        out.append(line)
    return "\n".join(out) + "\n"


def generate_crosscheck(out: Path, directory: Path) -> None:
    """The cross-check report, with its figures addressed from the site's root."""
    report = directory / "report.md"
    text = report.read_text(encoding="utf-8") if report.is_file() else (
        "No report yet: `make crosscheck` writes it.\n")
    text = re.sub(r"\]\((?!https?:|/)([^)]+\.png)\)", rf"](/{directory.name}/\1)", text)
    write_if_changed(out / "include" / "crosscheck_report.md", table_safe(text))


# ---------------------------------------------------------------------------
# Command line


def cli_commands() -> list[tuple[str, list[str]]]:
    """(command as a user types it, argv of ``python -m``) of ``seaice`` and
    each of its sub-commands."""
    from seaice_gym.cli import COMMANDS

    return [("seaice", ["seaice_gym"])] + [(f"seaice {s}", ["seaice_gym", s]) for s in COMMANDS]


def _help(argv: list[str]) -> str:
    env = dict(os.environ, COLUMNS="88", SEAICE_QUIET="1", PYTHONWARNINGS="ignore")
    done = subprocess.run([sys.executable, "-m", *argv, "--help"], capture_output=True,
                          text=True, env=env, timeout=300)
    if done.returncode != 0:
        raise RuntimeError(f"python -m {' '.join(argv)} --help failed:\n{done.stderr}")
    return done.stdout


def generate_cli(out: Path) -> None:
    commands = cli_commands()
    with ThreadPoolExecutor(2) as pool:
        helps = list(pool.map(_help, [argv for _, argv in commands]))
    lines = []
    for (command, argv), text in zip(commands, helps):
        lines += [f"## `{command}`", "",
                  f"(also `python -m {' '.join(argv)}`)" if command.startswith("seaice") else "",
                  "", "```text", text.rstrip(), "```", ""]
    write_if_changed(out / "include" / "cli.md", "\n".join(lines))


def generate_scenario_parameters(out: Path) -> None:
    from physics.scenarios.config import bundled_configs, load_config

    lines = []
    for name, path in bundled_configs().items():
        cfg = load_config(path)
        lines += [f"### `{name}`", "", f"**{cfg.title}.** Reproduces {cfg.reproduces}.", "",
                  cfg.description, "",
                  f"File: `physics/scenarios/configs/{path.name}`", "",
                  "| parameter | default | `--quick` | units | allowed | meaning |",
                  "|---|---|---|---|---|---|"]
        for key, p in cfg.params.items():
            quick = cfg.quick.get(key, "")
            lines.append(f"| `{key}` | `{p.default}` | {f'`{quick}`' if quick != '' else ''} | "
                         f"{p.units} | {_cell(p.allowed())} | {_cell(p.help)} |")
        lines.append("")
    write_if_changed(out / "include" / "scenario_parameters.md", "\n".join(lines))


# ---------------------------------------------------------------------------
# API reference


def public_modules() -> list[tuple[str, bool]]:
    """(name, is a package) of every public module of :data:`API_PACKAGES`,
    walked from the packages (no private module, no ``__main__``)."""
    found = []
    for package in API_PACKAGES:
        pkg = importlib.import_module(package)
        found.append((package, True))
        for info in pkgutil.walk_packages(pkg.__path__, prefix=package + "."):
            parts = info.name.split(".")
            if any(p.startswith("_") for p in parts):
                continue
            found.append((info.name, info.ispkg))
    return found


def generate_api(out: Path) -> None:
    found = public_modules()
    modules = [name for name, _ in found]
    api = out / "api"
    for name, package in found:
        source = name.replace(".", "/") + ("/__init__.py" if package else ".py")
        write_if_changed(api / f"{name}.md", "\n".join([
            f"# {name}", "", f"Source: `{source}`", "",
            "```{eval-rst}", f".. automodule:: {name}", "```", ""]))
    for stale in api.glob("*.md"):
        if stale.stem not in modules:
            stale.unlink()
    toc = ["```{toctree}", ":maxdepth: 1", ""] + [f"/_generated/api/{m}" for m in modules]
    write_if_changed(out / "include" / "api_toc.md", "\n".join(toc + ["```", ""]))


# ---------------------------------------------------------------------------
# Sphinx hooks


def exact_step_records(manifest: Path) -> str:
    """A Markdown list of the records of ``docs/records.yaml`` made with the
    exact engine step (``step: exact``), each with its page and what it holds."""
    import yaml

    entries = yaml.safe_load(manifest.read_text(encoding="utf-8"))["records"]
    lines = [f"* `{e['path'].removeprefix('docs/')}` ({{doc}}`/{Path(e['page']).stem}`): "
             f"{e.get('what', '')}" for e in entries if e.get("step") == "exact"]
    return "\n".join(lines) if lines else "None."


def on_builder_inited(app) -> None:
    os.environ.setdefault("SEAICE_QUIET", "1")
    src = Path(app.srcdir)
    out = src / "_generated"
    generate_environments(out)
    generate_benchmarks(out, src / "benchmarks")
    generate_crosscheck(out, src / "crosscheck")
    generate_cli(out)
    generate_scenario_parameters(out)
    generate_api(out)
    write_if_changed(out / "include" / "observations.md", observation_table() + "\n")
    write_if_changed(out / "include" / "exact_step_records.md",
                     exact_step_records(src / "records.yaml") + "\n")
    app.env_pages = {environment_class(spec): env_id
                     for env_id, spec in registered_environments()}


_LITERAL = re.compile(r"(``.+?``|:\w+(?::\w+)?:`[^`]*`|`[^`]*`_?)")


def escape_bars(lines: list[str]) -> list[str]:
    """``|x|`` (an absolute value) outside literals, as plain text: reST would
    read it as a substitution. Literal blocks and doctests are left alone."""
    out, literal_indent = [], None
    for line in lines:
        stripped = line.lstrip()
        indent = len(line) - len(stripped)
        if literal_indent is not None and stripped and indent <= literal_indent:
            literal_indent = None
        if literal_indent is None and stripped and not stripped.startswith(">>>"):
            parts = _LITERAL.split(line)
            line = "".join(p if k % 2 else p.replace("|", "\\|") for k, p in enumerate(parts))
        if stripped.endswith("::"):
            literal_indent = indent
        out.append(line)
    return out


def on_process_docstring(app, what, name, obj, options, lines) -> None:
    """An environment's class docstring is Markdown: its page renders it, the
    API page points there. Absolute-value bars are escaped."""
    env_id = getattr(app, "env_pages", {}).get(obj) if what == "class" else None
    if env_id is not None:
        page = "/_generated/environments/" + env_id.split("/")[-1]
        lines[:] = [f"The environment ``{env_id}``; its specification (description, "
                    f"spaces, rewards, task parameters) is on its page, :doc:`{page}`."]
        return
    lines[:] = escape_bars(lines)


def on_skip_member(app, what, name, obj, skip, options):
    """Leave out the generated field accessors of named tuples (their fields
    are listed in the class docstring)."""
    if (getattr(obj, "__doc__", None) or "").startswith("Alias for field number"):
        return True
    return None


def setup(app):
    app.connect("builder-inited", on_builder_inited)
    app.connect("autodoc-process-docstring", on_process_docstring)
    app.connect("autodoc-skip-member", on_skip_member)
    return {"version": "1", "parallel_read_safe": True, "parallel_write_safe": True}
