"""The headline figures in the README, from the benchmarks' records:
``python -m benchmarks.headline [--readme README.md] [--records docs/benchmarks]``.

Rewrites the block between ``<!-- headline:start -->`` and
``<!-- headline:end -->`` with one small table: the Hertz engine's
floe-steps/s at Ā = 0.7 and jammed, each with its contacts per floe and a
line on what the two regimes cost, the hard-disc engine's collisions/s and
each environment's sustained steps/s, the native vector environments'
steps/s and PPO's training steps/s on them, ShipNavigation-v1 under each
engine step over whole transits, as far as records of full runs
(not ``--quick``) exist, each with its date.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

from . import harness

START = "<!-- headline:start -->"
END = "<!-- headline:end -->"
#: the documentation page with every table, relative to the README
BENCHMARKS_PAGE = "docs/benchmarks.md"
#: contacts per floe below which the floes of a Hertz case are said to be in
#: free flight (then at most one floe in a hundred touches another)
FREE_FLIGHT = 0.01


def _hertz_cases(record: dict) -> list[dict]:
    """The timed cases of a Hertz record, in its order: name, contacts per
    floe and its fastest and serial rows.

    Raises
    ------
    ValueError
        If a case has no contacts per floe: a floe-step's cost depends on how
        often the floes touch, so a figure without it says nothing.
    """
    rows = record["data"]["rows"]
    out = []
    for case in dict.fromkeys(r["case"] for r in rows):
        if not case.startswith(("Ā =", "jammed")):
            continue
        timed = [r for r in rows if r["case"] == case]
        z = timed[0].get("contacts_per_floe")
        if not isinstance(z, (int, float)) or not z >= 0.0:
            raise ValueError(f"the Hertz record of {record['date'][:10]} has no contacts per "
                             f"floe for the case {case!r} (found {z!r}); rerun "
                             f"`seaice bench hertz`, which records them")
        serial = [r for r in timed if r["kernel"] == "serial"]
        most = max(timed, key=lambda r: (r["kernel"] == "parallel", r["threads"]))
        out.append(dict(case=case, contacts=float(z), most=most,
                        serial=serial[0] if serial else None))
    return out


def _hertz_rows(record: dict) -> list[list[str]]:
    out = []
    for c in _hertz_cases(record):
        most, serial = c["most"], c["serial"]
        figure = f"{most['rate']:.3g} floe-steps/s on {most['threads']} thread" \
                 f"{'s' * (most['threads'] > 1)}"
        if serial and most is not serial:
            figure += f" ({serial['rate']:.3g} on one, serial kernels)"
        out.append([f"Hertz engine, N = {record['data']['n']}, {c['case']}, "
                    f"{harness.format_number(c['contacts'])} contacts per floe", figure])
    return out


def _hertz_note(record: dict) -> str:
    """What the Hertz figures measure: the sparsest and the densest case,
    their contacts per floe and how much more a floe-step of the dense one
    costs at the same number of threads."""
    cases = _hertz_cases(record)
    if len(cases) < 2:
        return ""
    loose = min(cases, key=lambda c: c["contacts"])
    dense = max(cases, key=lambda c: c["contacts"])
    same = [r for r in record["data"]["rows"] if r["case"] == loose["case"]
            and r["kernel"] == dense["most"]["kernel"] and r["threads"] == dense["most"]["threads"]]
    if loose is dense or not same:
        return ""
    ratio = same[0]["rate"] / dense["most"]["rate"]
    threads = dense["most"]["threads"]
    # fewer than one floe in a hundred touching: nearly all drift untouched
    free = " (nearly all its floes in free flight)" if loose["contacts"] < FREE_FLIGHT else ""
    return (f"The Hertz engine's speed depends on how often floes touch: the "
            f"{loose['case']} field has {harness.format_number(loose['contacts'])} contacts "
            f"per floe{free}; in the {dense['case']} field, with "
            f"{harness.format_number(dense['contacts'])} contacts per floe, a floe-step costs "
            f"{ratio:.3g} times as much on {threads} thread{'s' * (threads > 1)}.")


def _harddisk_rows(record: dict) -> list[list[str]]:
    return [[f"Hard-disc engine, {r['case']}", f"{r['rate']:.3g} collisions/s, one core"]
            for r in record["data"]["rows"]]


def _environment_rows(record: dict) -> list[list[str]]:
    return [[f"`{r['id']}`", f"{r['mean']:.0f} steps/s, one core"]
            for r in record["data"]["environments"] if "failed" not in r]


def _vector_rows(record: dict) -> list[list[str]]:
    """The native vector environment at its largest N against the single
    environment of the same run, and PPO end to end with it."""
    data = record["data"]
    out = []
    for env_id in data["settings"]["ids"]:
        rows = [r for r in data["stepping"] if r["id"] == env_id and "failed" not in r]
        single = [r for r in rows if r["mode"] == "single"]
        native = [r for r in rows if r["mode"] == "native"]
        if not single or not native:
            continue
        best = max(native, key=lambda r: r["mean"])
        out.append([f"`{env_id}`, native vector environment, N = {best['n']}",
                    f"{best['mean']:.0f} steps/s on {record['machine']['numba_threads']} "
                    f"threads ({single[0]['mean']:.0f} single, one core)"])
    for r in data.get("training", []):
        if r["mode"] == "native" and "failed" not in r:
            out.append([f"PPO on `{r['id']}`, native vector environment, N = {r['n']}",
                        f"{r['mean']:.0f} training steps/s end to end"])
    return out


def _free_drift_rows(record: dict) -> list[list[str]]:
    """ShipNavigation-v1 under each engine step, sustained over whole
    transits at A = 0.2–0.5 (the equivalence test's straight-line episodes,
    one core each, two side by side), from the main record of the suite
    (not the pilot's, not an extension's over fewer concentrations, not
    another environment's)."""
    from .bench_free_drift import ENV_ID, ENVS, REFERENCE

    settings = record["data"].get("settings", {})
    stats = record["data"].get("statistics")
    if (settings.get("env", ENV_ID) != ENV_ID or settings.get("statistic") == "control"
            or list(settings.get("concentrations", ())) != list(ENVS[ENV_ID]["concentrations"])
            or not stats or not stats.get("rates")):
        return []
    rates = {r["step"]: r["pooled"] for r in stats["rates"]}
    others = ", ".join(f"{rates[s]:.0f} {s}" for s in rates if s not in (REFERENCE, "fast"))
    a = "–".join(f"{float(x):g}" for x in (settings["concentrations"][0],
                                           settings["concentrations"][-1]))
    return [[f"`{ENV_ID}`, sustained over whole transits, A = {a}",
             f"{rates['fast']:.0f} steps/s with the default (fast) step, "
             f"{rates[REFERENCE]:.0f} with the exact step" + (f"; soft ice: {others}"
                                                              if others else "")
             + "; one core each, two runs side by side"]]


_ROWS = {"hertz": _hertz_rows, "harddisk": _harddisk_rows, "environments": _environment_rows,
         "vector": _vector_rows, "free_drift": _free_drift_rows}


def headline_table(records: list[dict]) -> str:
    """The Markdown of the headline block (without the markers)."""
    rows, machines, notes = [], [], []
    for record in records:
        if record.get("suite") not in _ROWS or record.get("data", {}).get("quick"):
            continue
        if record["suite"] == "environments" and "environments" not in record["data"]:
            continue                                   # the stiffness table
        rows += [[what, figure, record["date"][:10]]
                 for what, figure in _ROWS[record["suite"]](record)]
        machines.append(record["machine"].get("cpu") or "?")
        if record["suite"] == "hertz":
            notes.append(_hertz_note(record))
    if not rows:
        return "No benchmark records yet: `make records` measures them."
    lines = ["| benchmark | figure | measured |", "|---|---|---|"]
    lines += ["| " + " | ".join(r) + " |" for r in rows]
    lines += [line for note in notes if note for line in ("", note)]
    lines += ["", f"Measured on {', '.join(dict.fromkeys(machines))} with `make records`; "
                  f"commands, machines and every table are on the "
                  f"[Benchmarks]({BENCHMARKS_PAGE}) page."]
    return "\n".join(lines)


def rewrite(text: str, records: list[dict]) -> str:
    """``text`` with the block between the markers replaced by
    :func:`headline_table`.

    Raises
    ------
    ValueError
        If the markers are missing, repeated or out of order.
    """
    start, end = text.count(START), text.count(END)
    if start != 1 or end != 1 or text.index(START) > text.index(END):
        raise ValueError(f"the README needs one line {START} and, after it, one line {END} "
                         f"around the headline figures (found {start} and {end})")
    head, rest = text.split(START)
    _, tail = rest.split(END)
    return f"{head}{START}\n{headline_table(records)}\n{END}{tail}"


def main(argv=None, prog: str | None = None) -> int:
    p = argparse.ArgumentParser(prog=prog or "python -m benchmarks.headline",
                                description=__doc__.split("\n\n")[1],
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    readme, records = harness.ROOT / "README.md", harness.DOCS_DIR
    p.add_argument("--readme", type=Path, default=readme,
                   help=f"the file to rewrite (default {harness.in_checkout(readme)})")
    p.add_argument("--records", type=Path, default=records,
                   help=f"where the records are (default {harness.in_checkout(records)})")
    args = p.parse_args(argv)
    try:
        text = args.readme.read_text(encoding="utf-8")
        new = rewrite(text, harness.load_records(args.records))
    except (OSError, ValueError) as exc:
        print(f"python -m benchmarks.headline: {args.readme}: {exc}", file=sys.stderr)
        return 1
    if new != text:
        args.readme.write_text(new, encoding="utf-8")
    print(f"headline figures written to {args.readme}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
