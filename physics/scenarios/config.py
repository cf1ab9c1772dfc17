"""Scenario parameter files: loading, ``--set key=value`` overrides, validation.

A scenario is described by a YAML file (``physics/scenarios/configs/NAME.yaml``;
copy one, edit it and pass its path to ``ice-scenarios run``)::

    name: herman2013-convergence        # the experiment that runs it
    title: Pure convergence without wind
    reproduces: Herman (2013), Figs 1a, 2 and 3
    description: >
      What the scenario does and what to look for.
    parameters:
      floes:  {default: 20000, min: 100, max: 200000, help: number of floes}
      rate:   {default: 0.04, min: 0.0, min_open: true, units: 1/h, help: dA/dt}
      engine: {default: hertz, choices: [hertz, harddisk], help: ...}
      concentrations: {default: [0.6, 0.7], item_min: 0.1, item_max: 0.9, help: ...}
    quick:                              # overrides of --quick
      floes: 800

Every parameter has a default, a help text and a range (``min``/``max``,
open with ``min_open``/``max_open``) or a list of ``choices``; lists check
each item against ``item_min``/``item_max``. The type follows the default
(int, float, bool, str or a list of numbers).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

CONFIG_DIR = Path(__file__).with_name("configs")

_SPEC_KEYS = {"default", "help", "units", "min", "max", "min_open", "max_open", "choices",
              "item_min", "item_max"}


def _yaml():
    try:
        import yaml
    except ImportError:  # pragma: no cover - the plots extra brings it
        raise ImportError("scenario files need PyYAML: pip install 'seaice-gym[plots]'") from None
    return yaml


@dataclass(frozen=True)
class Param:
    """One scenario parameter: its default, allowed values and meaning."""

    name: str
    default: Any
    help: str
    units: str = ""
    min: float | None = None
    max: float | None = None
    min_open: bool = False
    max_open: bool = False
    choices: tuple | None = None
    item_min: float | None = None
    item_max: float | None = None

    @property
    def kind(self) -> type:
        return type(self.default)

    def allowed(self) -> str:
        """The allowed values in words (for messages and ``show``)."""
        if self.choices is not None:
            return "one of " + ", ".join(map(str, self.choices))
        if isinstance(self.default, bool):
            return "true or false"
        if isinstance(self.default, list):
            return f"a list of numbers in {_interval(self.item_min, self.item_max)}"
        return (("an integer" if isinstance(self.default, int) else "a number") + " in "
                + _interval(self.min, self.max, self.min_open, self.max_open))

    def check(self, value: Any) -> Any:
        """``value`` converted to the parameter's type, or ``ValueError``
        naming the parameter, the value and the allowed range."""
        bad = ValueError(f"parameter {self.name!r} must be {self.allowed()}, got {value!r}")
        kind = self.kind
        if kind is bool:
            if isinstance(value, bool):
                return value
            if isinstance(value, str) and value.lower() in ("true", "false", "yes", "no"):
                return value.lower() in ("true", "yes")
            raise bad
        if kind is list:
            if not isinstance(value, (list, tuple)):
                raise bad
            try:
                items = [float(v) for v in value]
            except (TypeError, ValueError):
                raise bad from None
            for v in items:
                if not math.isfinite(v) or not _inside(v, self.item_min, self.item_max):
                    raise bad
            return items
        if kind is str:
            value = str(value)
        elif kind is int:
            if isinstance(value, bool) or not isinstance(value, (int, float, str)):
                raise bad
            try:
                f = float(value)
            except ValueError:
                raise bad from None
            if not math.isfinite(f) or f != int(f):
                raise bad
            value = int(f)
        elif kind is float:
            if isinstance(value, bool):
                raise bad
            try:
                value = float(value)
            except (TypeError, ValueError):
                raise bad from None
            if not math.isfinite(value):
                raise bad
        if self.choices is not None:
            if value not in self.choices:
                raise bad
            return value
        if kind in (int, float) and not _inside(value, self.min, self.max, self.min_open,
                                                 self.max_open):
            raise bad
        return value


def _interval(lo, hi, lo_open=False, hi_open=False) -> str:
    a = "(-inf" if lo is None else f"{'(' if lo_open else '['}{lo:g}"
    b = "inf)" if hi is None else f"{hi:g}{')' if hi_open else ']'}"
    return f"{a}, {b}"


def _inside(v, lo, hi, lo_open=False, hi_open=False) -> bool:
    if lo is not None and (v <= lo if lo_open else v < lo):
        return False
    if hi is not None and (v >= hi if hi_open else v > hi):
        return False
    return True


@dataclass
class ScenarioConfig:
    """A scenario file, parsed: metadata, parameter specs and quick overrides."""

    name: str
    title: str
    reproduces: str
    description: str
    params: dict[str, Param]
    quick: dict[str, Any] = field(default_factory=dict)
    path: Path | None = None
    #: the file's mapping as read (stored with a run, so it resumes even if the file changes)
    data: dict = field(default_factory=dict)

    def defaults(self, quick: bool = False) -> dict[str, Any]:
        values = {k: p.default for k, p in self.params.items()}
        if quick:
            values.update(self.quick)
        return values

    def resolve(self, overrides: dict[str, Any] | None = None, *, quick: bool = False) -> dict:
        """Defaults (with the quick overrides if asked), then ``overrides``,
        every value checked. Unknown names raise ``ValueError`` listing the
        valid ones."""
        values = self.defaults(quick)
        for key, value in (overrides or {}).items():
            if key not in self.params:
                raise ValueError(f"unknown parameter {key!r} for scenario {self.name!r}; "
                                 f"valid parameters: {', '.join(self.params)}")
            values[key] = value
        return {k: self.params[k].check(v) for k, v in values.items()}


def parse_config(data: dict, path: Path | None = None) -> ScenarioConfig:
    """A :class:`ScenarioConfig` from the parsed YAML mapping ``data``."""
    where = f" in {path}" if path else ""
    if not isinstance(data, dict):
        raise ValueError(f"a scenario file must be a mapping{where}")
    missing = [k for k in ("name", "title", "parameters") if k not in data]
    if missing:
        raise ValueError(f"scenario file{where} lacks {', '.join(missing)}")
    params = {}
    for name, spec in data["parameters"].items():
        if not isinstance(spec, dict) or "default" not in spec or "help" not in spec:
            raise ValueError(f"parameter {name!r}{where} needs at least 'default' and 'help'")
        unknown = set(spec) - _SPEC_KEYS
        if unknown:
            raise ValueError(f"parameter {name!r}{where} has unknown keys {sorted(unknown)}; "
                             f"valid keys: {', '.join(sorted(_SPEC_KEYS))}")
        spec = dict(spec)
        if "choices" in spec:
            spec["choices"] = tuple(spec["choices"])
        p = Param(name=name, **spec)
        p.check(p.default)            # a default outside its own range is a file error
        params[name] = p
    cfg = ScenarioConfig(name=data["name"], title=data["title"],
                         reproduces=data.get("reproduces", ""),
                         description=data.get("description", "").strip(), params=params,
                         quick=dict(data.get("quick") or {}), path=path, data=data)
    cfg.resolve(quick=True)             # quick overrides must be valid too
    return cfg


def load_config(path) -> ScenarioConfig:
    """Read and check a scenario file."""
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"no scenario file {path}")
    yaml = _yaml()
    with open(path) as fh:
        try:
            data = yaml.safe_load(fh)
        except yaml.YAMLError as exc:
            raise ValueError(f"scenario file {path} is not valid YAML: {exc}") from None
    return parse_config(data, path)


def bundled_configs() -> dict[str, Path]:
    """Scenario name → path of the file shipped with the package."""
    return {p.stem: p for p in sorted(CONFIG_DIR.glob("*.yaml"))}


#: words that YAML 1.1 reads as booleans but that name choices here
#: (``--set wind=off``): they stay text; ``true`` and ``false`` are booleans
_WORDS = {"on", "off", "yes", "no", "y", "n"}


def parse_set(items) -> dict[str, Any]:
    """``["key=value", ...]`` (values in YAML syntax: 0.5, true, [0.6, 0.7];
    ``on``, ``off``, ``yes`` and ``no`` stay words) → dict."""
    out = {}
    for item in items or ():
        if "=" not in item:
            raise ValueError(f"--set expects key=value, got {item!r}")
        key, text = item.split("=", 1)
        key = key.strip()
        if not key:
            raise ValueError(f"--set expects key=value, got {item!r}")
        if text.strip().lower() in _WORDS:
            out[key] = text.strip()
            continue
        yaml = _yaml()
        try:
            out[key] = yaml.safe_load(text)
        except yaml.YAMLError:          # not YAML: the value is the text itself
            out[key] = text
    return out


def dump_yaml(data) -> str:
    return _yaml().safe_dump(data, sort_keys=False, allow_unicode=True)
