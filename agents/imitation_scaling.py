"""How a waypoint student's imitation error falls with the labels it is
fitted on: the students of one DAgger labelling, fitted again on nested
shares of its fields and judged on fields none of them saw.

A waypoint student (:mod:`agents.waypoints`) misses its teacher's
decisions by a share of their variance, and an error of a given share
costs a given return (:mod:`agents.imitation_error`). Whether more labels
would make a student precise enough is a question of how that share falls
with the labels. A run trained with ``--keep-labels`` keeps every
labelled decision with its round and its field (:data:`LABELS`), so it
can be answered from one labelling:

* **The split.** In each DAgger round, ``test_fields`` of the round's
  fields, drawn by a generator seeded by the run's seed, are kept for the
  test; the rest are the training fields. The test fields hold decisions
  of every round, so the test is on the states the rounds visited (the
  student's own as well as the teacher's). The run's held-out fields,
  sailed by the teacher alone, are a second test.
* **The fits.** For each share f of ``fractions``, the first ⌈f n⌉ of
  each round's training fields (n of them; one order a round, drawn by the
  same generator, so the shares are nested) are fitted by the run's own
  recipe: a new network seeded by the run's seed, fitted by Adam on the
  decisions and their mirror images, with the labels clipped to [−1, 1],
  for ``epochs`` / f epochs (the same number of gradient steps at every
  share, so that a small share is not also fitted less; ``scale_epochs``
  False: ``epochs`` at every share). ``extra_epochs`` fit all the
  training fields again for each number of epochs given, to see whether
  the recipe's fit stops short.
* **The error**, on each test, is the squared distance of the student's
  decision (clipped to [−1, 1], as it is sailed) from the teacher's
  (clipped), as a share of the teacher's decisions' variance: the
  measure of the training tables.
* **The law.** A straight line fitted to log error against log labelled
  decisions gives the exponent α of error ∝ n^−α: over all the shares,
  and over the two largest alone (where the error has fallen least, the
  line to follow further), with the decisions at which the latter
  reaches each of ``targets``. Read them as an extrapolation beyond the
  data, not a measurement.

Run, on runs trained with ``--keep-labels``::

    python -m agents.imitation_scaling RUN [RUN ...] --out DIR

It writes ``DIR/scaling.json`` (settings, each fit's error on both tests,
each run's laws), ``DIR/scaling.md`` (tables) and ``DIR/scaling.png``
(error against labelled decisions, the laws and the targets).
``--render --out DIR`` writes the laws, tables and figure again from
``DIR/scaling.json``, without fitting.
"""
from __future__ import annotations

import argparse
import json
import math
import shlex
import sys
import time
from pathlib import Path

import numpy as np

__all__ = ["SCALING_DEFAULTS", "load_labels", "split_fields", "refit_error", "power_law",
           "laws_of", "scaling", "render", "scaling_markdown", "plot_scaling", "main", "RECORD"]

#: the record, its tables and its figure, in the output directory
RECORD, TABLE, FIGURE = "scaling.json", "scaling.md", "scaling.png"

#: the settings of :func:`scaling`
SCALING_DEFAULTS = dict(fractions=(0.125, 0.25, 0.5, 1.0), test_fields=10, epochs=5,
                        scale_epochs=True, extra_epochs=(), targets=(0.01, 0.005),
                        processes=1)


def load_labels(run, keys=None) -> dict:
    """The labelled decisions of the run directory ``run``
    (:data:`agents.waypoints.LABELS`) and its record's settings, as a dict
    of arrays and ``settings``; ``keys``: only those arrays (None: all;
    the costmaps are most of a run's labels)."""
    from .waypoints import LABELS, RECORD as TRAIN_RECORD

    path, record = Path(run) / LABELS, Path(run) / TRAIN_RECORD
    if not record.is_file():
        raise FileNotFoundError(f"{run}: no {TRAIN_RECORD} (not a run of python -m "
                                f"agents.waypoints train)")
    if not path.is_file():
        raise FileNotFoundError(f"{run}: no {LABELS} (train the run with --keep-labels)")
    settings = json.loads(record.read_text())["settings"]
    if settings.get("form", "waypoints") != "waypoints":
        raise ValueError(f"{run}: a run of form {settings['form']!r}; the error's share of the "
                         "variance is defined for waypoint decisions only")
    with np.load(path) as data:
        out = {k: data[k] for k in (data.files if keys is None else keys)}
    return {**out, "settings": settings}


def split_fields(rounds: np.ndarray, fields: np.ndarray, test_fields: int, fractions,
                 seed: int) -> tuple[np.ndarray, list[np.ndarray]]:
    """The test decisions and, for each share of ``fractions``, the training
    decisions, as boolean masks over the decisions of ``rounds`` and
    ``fields`` (one entry a decision): in each round ``test_fields`` of
    its fields for the test, and of the others, in one order a round, the
    first ⌈f n⌉ (at least one) for the share f; all drawn by a generator
    seeded by ``seed``."""
    rounds, fields = np.asarray(rounds), np.asarray(fields)
    if rounds.shape != fields.shape or rounds.ndim != 1:
        raise ValueError("rounds and fields must be one entry a decision, of one length")
    fractions = [float(f) for f in fractions]
    if not fractions or any(not 0.0 < f <= 1.0 for f in fractions):
        raise ValueError(f"fractions must be shares in (0, 1], got {fractions}")
    if isinstance(test_fields, bool) or int(test_fields) != test_fields or test_fields < 0:
        raise ValueError(f"test_fields must be an integer >= 0, got {test_fields!r}")
    rng = np.random.default_rng(int(seed))
    test = np.zeros(len(rounds), dtype=bool)
    train = [np.zeros(len(rounds), dtype=bool) for _ in fractions]
    for r in np.unique(rounds):
        own = np.unique(fields[rounds == r])
        if len(own) <= test_fields:
            raise ValueError(f"round {r} has {len(own)} fields: too few to keep {test_fields} "
                             "for the test and fit on the rest")
        order = rng.permutation(own)
        held, rest = order[:test_fields], order[test_fields:]
        in_round = rounds == r
        test |= in_round & np.isin(fields, held)
        for mask, f in zip(train, fractions):
            mask |= in_round & np.isin(fields, rest[:max(1, math.ceil(f * len(rest)))])
    return test, train


def _decisions(policy, seen: dict, chunk: int = 512) -> np.ndarray:
    """The deterministic decisions of ``policy`` on the batch ``seen``, in
    chunks (clipped to its action space, as they are sailed)."""
    out = [policy.predict({k: v[i:i + chunk] for k, v in seen.items()}, deterministic=True)[0]
           for i in range(0, len(next(iter(seen.values()))), chunk)]
    return np.concatenate(out).astype(float)


def _share(policy, seen: dict, labels: np.ndarray) -> float:
    wanted = np.clip(labels, -1.0, 1.0)
    return float(np.mean((_decisions(policy, seen) - wanted) ** 2) / max(np.var(wanted), 1e-12))


def refit_error(data: dict, train: np.ndarray, tests: dict, epochs: int, fit_seed: int) -> dict:
    """Fit a new student on the decisions ``train`` (a mask) of ``data``
    (:func:`load_labels`) by its run's recipe, for ``epochs`` epochs with
    the fit seeded ``fit_seed``; returns its error's share of the
    variance on each of ``tests`` (name: mask over the run's decisions, or
    ``"held"`` for the run's held-out fields) and on its own decisions."""
    import gymnasium as gym

    import iceenvs  # noqa: F401  (registers the ids)

    from .pretrain import fit_policy
    from .waypoints import make_student, with_mirror

    s = data["settings"]
    env = gym.make(s["env_id"], **s["env_kwargs"])
    try:
        policy = make_student(env, form="waypoints", points=s["points"], cnn_dim=s["cnn_dim"],
                              learning_rate=s["learning_rate"], seed=s["seed"])
    finally:
        env.close()
    seen = {k: data[k][train] for k in ("costmap", "vector")}
    labels = np.clip(data["labels"][train], -1.0, 1.0)
    if s.get("mirror", True):
        seen, labels = with_mirror(seen, labels)
    began = time.perf_counter()
    fit = fit_policy(policy, seen, labels, None, epochs=int(epochs), batch_size=s["batch_size"],
                     learning_rate=s["learning_rate"], seed=int(fit_seed))
    seconds = time.perf_counter() - began
    del seen
    policy.set_training_mode(False)
    out = {"decisions": int(train.sum()), "epochs": int(epochs),
           "own": fit["action_mse"] / max(fit["action_variance"], 1e-12),
           "seconds": round(seconds, 1)}
    for name, mask in tests.items():
        if name == "held":
            out[name] = _share(policy, {"costmap": data["held_costmap"],
                                        "vector": data["held_vector"]}, data["held_labels"])
        else:
            out[name] = _share(policy, {k: data[k][mask] for k in ("costmap", "vector")},
                               data["labels"][mask])
    return out


#: log of the decisions beyond which a law's reach is given as None
_LOG_FAR = 300 * math.log(10.0)


def power_law(decisions, errors, targets=()) -> dict:
    """The straight line through (log decisions, log errors) by least
    squares: error ≈ c · n^−α, and the decisions n at which it reaches
    each of ``targets`` (None where the line does not fall, or reaches it
    only beyond 10^300 decisions)."""
    n, e = np.asarray(decisions, dtype=float), np.asarray(errors, dtype=float)
    if len(n) < 2 or n.shape != e.shape or np.any(n <= 0) or np.any(e <= 0):
        raise ValueError("a law needs two or more positive (decisions, error) pairs")
    slope, intercept = np.polyfit(np.log(n), np.log(e), 1)
    alpha = -float(slope)
    reach = {}
    for t in targets:
        log_n = (intercept - math.log(t)) / alpha if alpha > 0 else math.inf
        reach[f"{t:g}"] = float(math.exp(log_n)) if log_n < _LOG_FAR else None
    return {"alpha": alpha, "c": float(math.exp(intercept)), "decisions_for": reach}


def _one_thread():
    import torch

    torch.set_num_threads(1)


def _job(args):
    run, key, train_index, epochs, fit_seed, test_fields, fractions = args
    data = load_labels(run)
    s = data["settings"]
    test, trains = split_fields(data["round"], data["field"], test_fields, fractions, s["seed"])
    result = refit_error(data, trains[train_index], {"test": test, "held": None}, epochs,
                         fit_seed)
    return run, key, result


def scaling(runs, out: Path, progress: bool = True, command: str | None = None,
            **settings) -> dict:
    """Fit and judge the students of each run of ``runs`` (see the module's
    text) and write the record, tables and figure into ``out``; returns the
    record."""
    from concurrent.futures import ProcessPoolExecutor

    from tqdm.auto import tqdm

    unknown = sorted(set(settings) - set(SCALING_DEFAULTS))
    if unknown:
        raise ValueError(f"unknown settings {unknown}; valid: {', '.join(SCALING_DEFAULTS)}")
    s = {**SCALING_DEFAULTS, **settings}
    fractions = sorted(float(f) for f in s["fractions"])
    if len(set(fractions)) < 2 or any(not 0.0 < f <= 1.0 for f in fractions):
        raise ValueError(f"fractions must be two or more different shares in (0, 1], "
                         f"got {s['fractions']}")
    for name in ("epochs", "processes"):
        if isinstance(s[name], bool) or int(s[name]) != s[name] or s[name] < 1:
            raise ValueError(f"{name} must be an integer >= 1, got {s[name]!r}")
    extra = [int(e) for e in s["extra_epochs"]]
    if any(e < 1 for e in extra):
        raise ValueError(f"extra_epochs must be integers >= 1, got {s['extra_epochs']}")
    if extra and fractions[-1] != 1.0:
        raise ValueError(f"extra_epochs fit all the training fields: give the share 1 among "
                         f"the fractions, got {s['fractions']}")
    targets = [float(t) for t in s["targets"]]
    if any(not 0.0 < t < 1.0 for t in targets):
        raise ValueError(f"targets must be shares in (0, 1), got {s['targets']}")
    runs = [Path(r).as_posix() for r in runs]
    if not runs:
        raise ValueError("scaling needs at least one run")
    jobs = []
    for run in runs:
        data = load_labels(run, keys=("round", "field"))  # checks each run before any fit
        seed = int(data["settings"]["seed"])
        last = max(int(r) for r in np.unique(data["round"]))
        split_fields(data["round"], data["field"], s["test_fields"], fractions, seed)
        del data
        full = len(fractions) - 1
        for i, f in enumerate(fractions):
            epochs = max(1, round(s["epochs"] / f)) if s["scale_epochs"] else s["epochs"]
            jobs.append((run, f"share {f:g}", i, epochs, seed * 1000 + last, s["test_fields"],
                         fractions))
        for e in extra:
            jobs.append((run, f"all, {e} epochs", full, e, seed * 1000 + last, s["test_fields"],
                         fractions))
    began = time.perf_counter()
    results: dict = {run: {} for run in runs}
    bar = tqdm(total=len(jobs), desc="fits", unit="fit", disable=not progress)
    if s["processes"] == 1:
        for job in jobs:
            run, key, result = _job(job)
            results[run][key] = result
            bar.update()
    else:
        import multiprocessing

        with ProcessPoolExecutor(int(s["processes"]), initializer=_one_thread,
                                 mp_context=multiprocessing.get_context("spawn")) as pool:
            for run, key, result in pool.map(_job, jobs):
                results[run][key] = result
                bar.update()
    bar.close()
    settings = {**s, "fractions": fractions, "extra_epochs": extra, "targets": targets}
    record = {"settings": settings, "runs": results,
              "laws": laws_of(results, settings, {run: _labelling_rate(run) for run in runs}),
              "seconds": round(time.perf_counter() - began, 1), "command": command}
    return _write(record, out)


def laws_of(results: dict, settings: dict, rates: dict) -> dict:
    """Each run's laws (:func:`power_law`) on both tests, over all the shares
    (``test``, ``held``) and over the two largest (``test_last``,
    ``held_last``), with its pace of labelling (``rates``: decisions a
    second, by run)."""
    fractions = sorted(settings["fractions"])
    laws = {}
    for run, fits in results.items():
        shares = [fits[f"share {f:g}"] for f in fractions]
        laws[run] = {}
        for test in ("test", "held"):
            n, e = [r["decisions"] for r in shares], [r[test] for r in shares]
            laws[run][test] = power_law(n, e, settings["targets"])
            laws[run][test + "_last"] = power_law(n[-2:], e[-2:], settings["targets"])
        laws[run]["decisions_a_second"] = float(rates[run])
    return laws


def _write(record: dict, out) -> dict:
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    (out / RECORD).write_text(json.dumps(record, indent=1) + "\n")
    (out / TABLE).write_text(scaling_markdown(record))
    plot_scaling(record, out / FIGURE)
    return record


def render(out) -> dict:
    """Write the laws, tables and figure of ``out/scaling.json`` again (by
    this module's reading of its fits); returns the record."""
    path = Path(out) / RECORD
    if not path.is_file():
        raise FileNotFoundError(f"{out}: no {RECORD} (not a study of python -m "
                                "agents.imitation_scaling)")
    record = json.loads(path.read_text())
    rates = {run: law["decisions_a_second"] for run, law in record["laws"].items()}
    record["laws"] = laws_of(record["runs"], record["settings"], rates)
    return _write(record, out)


def _labelling_rate(run) -> float:
    """Decisions labelled a second of the run's training (its rounds'
    decisions over its rounds' seconds, fits included)."""
    from .waypoints import RECORD as TRAIN_RECORD

    record = json.loads((Path(run) / TRAIN_RECORD).read_text())
    return sum(r["decisions"] for r in record["rounds"]) / \
        max(sum(r["seconds"] for r in record["rounds"]), 1e-9)


def _hours(decisions, rate) -> str:
    if decisions is None:
        return "–"
    return f"{decisions:.3g} ({decisions / rate / 3600:.3g} h)"


def scaling_markdown(record: dict) -> str:
    """The record's tables: each fit's error on both tests, and each run's
    law with the decisions (and hours of labelling at the run's own pace)
    at which it reaches the targets."""
    s = record["settings"]
    lines = ["| run | fit | labelled decisions (without mirror images) | epochs "
             "| error on its own | on the test fields | on the held-out fields |",
             "|---|---|---|---|---|---|---|"]
    for run, fits in record["runs"].items():
        for key, r in fits.items():
            lines.append(f"| {run} | {key} | {r['decisions']} | {r['epochs']} | {r['own']:.3f} "
                         f"| {r['test']:.3f} | {r['held']:.3f} |")
    head = " | ".join(f"decisions for {t:g} (labelling hours)" for t in s["targets"])
    lines += ["", f"| run | test | α over all shares | α over the two largest | {head} |",
              "|---|---|---|---|" + "---|" * len(s["targets"])]
    names = {"test": "test fields", "held": "held-out fields"}
    for run, law in record["laws"].items():
        for test in ("test", "held"):
            last = law[test + "_last"]
            cells = " | ".join(_hours(last["decisions_for"][f"{t:g}"], law["decisions_a_second"])
                               for t in s["targets"])
            lines.append(f"| {run} | {names[test]} | {law[test]['alpha']:.2f} "
                         f"| {last['alpha']:.2f} | {cells} |")
    lines += ["", f"Errors are shares of the teacher's decisions' variance (decisions clipped "
              f"to [−1, 1]). Test: {s['test_fields']} fields a round kept from every fit; "
              f"held-out: the run's own held-out fields, sailed by the teacher. Shares "
              f"{', '.join(f'{f:g}' for f in s['fractions'])} of the other fields, fitted "
              + (f"for {s['epochs']} / share epochs" if s["scale_epochs"] else
                 f"for {s['epochs']} epochs")
              + ". The laws (error ∝ n^−α) are extrapolations; the decisions for each "
              "error are read on the line through the two largest shares, and their hours "
              "at the run's own pace of labelling (its rounds' decisions over their "
              f"seconds, fits included). {record['seconds']:.0f} s.", ""]
    return "\n".join(lines)


def plot_scaling(record: dict, path: Path) -> None:
    """Error against labelled decisions, log-log: each run's shares on both
    tests, its law through the two largest shares on the test fields
    (dashed), and the targets."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    s = record["settings"]
    fig, ax = plt.subplots(figsize=(6.4, 4.4))
    for i, (run, fits) in enumerate(record["runs"].items()):
        colour = f"C{i}"
        shares = [fits[f"share {f:g}"] for f in s["fractions"]]
        n = np.array([r["decisions"] for r in shares], dtype=float)
        ax.plot(n, [r["test"] for r in shares], "o-", color=colour, label=f"{run}: test fields")
        ax.plot(n, [r["held"] for r in shares], "s:", color=colour, alpha=0.6,
                label=f"{run}: held-out fields")
        law = record["laws"][run]["test_last"]
        far = max([n.max(), *[v for v in law["decisions_for"].values() if v]])
        grid = np.geomspace(n[-2], min(far, 1e3 * n.max()), 50)
        ax.plot(grid, law["c"] * grid ** -law["alpha"], "--", color=colour, lw=0.8)
    for t, style in zip(s["targets"], ["-.", ":", "--", "-"] * len(s["targets"])):
        ax.axhline(t, color="k", lw=0.7, ls=style, label=f"an error of {t:g}")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("labelled decisions fitted (without mirror images)")
    ax.set_ylabel("error / variance of the teacher's decisions")
    ax.set_title("Waypoint student: imitation error against labels", fontsize=10)
    ax.legend(fontsize=6, loc="lower left")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def _floats(text: str) -> list[float]:
    return [float(v) for v in text.split(",") if v.strip()]


def main(argv=None) -> int:
    argv = sys.argv[1:] if argv is None else list(argv)
    p = argparse.ArgumentParser(prog="python -m agents.imitation_scaling",
                                description=__doc__.split("\n\n")[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("runs", nargs="*", type=Path,
                   help="run directories of python -m agents.waypoints train --keep-labels")
    p.add_argument("--render", action="store_true",
                   help="write the laws, tables and figure of OUT/scaling.json again, without "
                        "fitting")
    p.add_argument("--out", type=Path, required=True)
    p.add_argument("--fractions", type=_floats,
                   default=list(SCALING_DEFAULTS["fractions"]),
                   help="shares of the training fields, comma-separated")
    p.add_argument("--test-fields", type=int, default=SCALING_DEFAULTS["test_fields"],
                   help="fields a round kept for the test")
    p.add_argument("--epochs", type=int, default=SCALING_DEFAULTS["epochs"],
                   help="epochs on all the training fields (a share f: epochs / f)")
    p.add_argument("--fixed-epochs", dest="scale_epochs", action="store_false",
                   help="fit every share for --epochs epochs, not epochs / share")
    p.add_argument("--extra-epochs", type=lambda t: [int(v) for v in _floats(t)], default=[],
                   help="fit all the training fields again for each of these epochs")
    p.add_argument("--targets", type=_floats, default=list(SCALING_DEFAULTS["targets"]),
                   help="errors (shares of the variance) the laws are read at")
    p.add_argument("--processes", type=int, default=1)
    p.add_argument("--no-progress", action="store_true")
    args = p.parse_args(argv)
    if args.render:
        if args.runs:
            p.error("--render reads OUT/scaling.json alone: give no runs")
        try:
            render(args.out)
        except FileNotFoundError as exc:
            p.error(str(exc))
        print(f"wrote {args.out}")
        return 0
    if not args.runs:
        p.error("give one or more run directories (or --render)")
    try:
        record = scaling(args.runs, args.out, progress=not args.no_progress,
                         command=shlex.join(["python", "-m", "agents.imitation_scaling", *argv]),
                         fractions=args.fractions, test_fields=args.test_fields,
                         epochs=args.epochs, scale_epochs=args.scale_epochs,
                         extra_epochs=args.extra_epochs, targets=args.targets,
                         processes=args.processes)
    except (ValueError, FileNotFoundError) as exc:
        p.error(str(exc))
    for run, law in record["laws"].items():
        print(f"{run}: error ∝ n^-{law['test']['alpha']:.2f} on the test fields "
              f"(n^-{law['test_last']['alpha']:.2f} over the two largest shares), "
              f"n^-{law['held']['alpha']:.2f} on the held-out fields")
    print(f"wrote {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
