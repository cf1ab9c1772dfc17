"""The policy protocol, and policies of one's own named by reference.

Everything that plays an episode here (:func:`agents.rollouts.run_episode`,
the evaluation, the leaderboard, the task checks) asks two things of a
policy, the :class:`Policy` protocol:

* ``predict(obs, deterministic=True) -> (action, state)``: the action for
  the environment's *raw* observation (an SB3 model's ``predict``; the state
  is ``None`` for a policy without memory);
* ``reset(seed)``: a new episode starts, from ``env.reset(seed=seed)``.

``close()`` is optional. Every baseline of :mod:`agents.baselines` keeps
the protocol: the generic ``*Policy`` ones of that module (they need only
the action space), the environments' ``*Controller`` ones of
:mod:`iceenvs` (they need only the environment) and the ``*Planner`` ones
of :mod:`agents.planners` (they may read privileged state); so does a
trained run (:class:`agents.rollouts.TrainedPolicy`).

A policy of one's own is named where a baseline's name is taken
(``agents.leaderboard --policies``, ``agents.evaluate --baseline`` and
``--baselines``, ``agents.tasks --policies``) by a reference:

* ``module:Class`` — a class of an importable module;
* ``path/to/file.py:Class`` — a class of a Python file;
* either with keyword arguments: ``module:Class?lookahead=200&gain=0.5`` (the
  values are read as YAML: numbers, booleans, strings).

The class is made as ``Class(env, seed=seed, **kwargs)`` for the
environment it plays: it may read the environment's facts (the names of
the observation entries, ``env.unwrapped.features``), and a planner the
privileged state (``env.unwrapped.ice_near``). Worker processes import it
themselves.

>>> check_reference("agents.baselines:ZeroPolicy")
'agents.baselines:ZeroPolicy'
"""
from __future__ import annotations

import importlib
import importlib.util
import sys
from pathlib import Path
from typing import Any, Protocol, runtime_checkable

__all__ = ["Policy", "is_reference", "parse_reference", "check_reference", "policy_class",
           "make_policy", "search_path"]


@runtime_checkable
class Policy(Protocol):
    """What an episode asks of a policy (see the module's text)."""

    def predict(self, obs: Any, deterministic: bool = True) -> tuple[Any, Any]:
        """(action, state) for the raw observation ``obs``."""

    def reset(self, seed: int | None = None) -> None:
        """A new episode starts, from ``env.reset(seed=seed)``."""


def is_reference(name: str) -> bool:
    """Whether ``name`` names a policy class (``module:Class``) rather than
    a baseline."""
    return ":" in name


def split_policies(text: str) -> list[str]:
    """The policies of a comma-separated list such as ``--policies``: a comma
    inside brackets belongs to an argument's value
    (``rollout-wide=agents.planners:RolloutPlanner?offsets=[-16,-4,4,16]``).

    Raises
    ------
    ValueError
        For brackets that do not close, or close before they open.
    """
    names, depth, start = [], 0, 0
    for i, char in enumerate(text):
        if char in "[{(":
            depth += 1
        elif char in "]})":
            depth -= 1
            if depth < 0:
                raise ValueError(f"policies {text!r}: {char!r} closes a bracket never opened")
        elif char == "," and depth == 0:
            names.append(text[start:i])
            start = i + 1
    if depth:
        raise ValueError(f"policies {text!r}: a bracket is not closed")
    names.append(text[start:])
    return [n.strip() for n in names if n.strip()]


def parse_reference(reference: str) -> tuple[str, str, dict]:
    """(module or file, class name, keyword arguments) of ``reference``.

    Raises
    ------
    ValueError
        For a reference without both parts, or a bad keyword argument.
    """
    import yaml

    text, _, query = reference.partition("?")
    target, _, name = text.rpartition(":")
    if not target or not name or not name.isidentifier():
        raise ValueError(f"policy {reference!r}: a policy is named module:Class or "
                         f"path/to/file.py:Class (then ?key=value&... for its arguments)")
    kwargs = {}
    for item in filter(None, query.split("&")):
        key, eq, value = item.partition("=")
        if not eq or not key.isidentifier():
            raise ValueError(f"policy {reference!r}: arguments are key=value pairs joined "
                             f"by '&', got {item!r}")
        kwargs[key] = yaml.safe_load(value)
    return target, name, kwargs


def _is_file(target: str) -> bool:
    return target.endswith(".py") or "/" in target or "\\" in target


def search_path(reference: str) -> list[str]:
    """Where a worker process finds the module of ``reference``: the
    directory it is imported from here (a file's reference needs none)."""
    target, _, _ = parse_reference(reference)
    if _is_file(target):
        return []
    try:
        spec = importlib.util.find_spec(target)
    except (ImportError, ValueError):
        return []
    if spec is None or not spec.origin or not Path(spec.origin).exists():
        return []
    root = Path(spec.origin).resolve().parent
    levels = target.count(".") + (1 if Path(spec.origin).name == "__init__.py" else 0)
    for _ in range(levels):
        root = root.parent
    return [str(root)]


def policy_class(reference: str, search: list[str] | tuple = ()) -> type:
    """The class ``reference`` names, imported (``search``: directories to
    import its module from, as :func:`search_path` gives them).

    Raises
    ------
    ValueError
        For a module or file that is missing or fails to import, a missing
        class, or a class without ``predict`` and ``reset``.
    """
    target, name, _ = parse_reference(reference)
    if _is_file(target):
        path = Path(target).expanduser().resolve()
        if not path.is_file():
            raise ValueError(f"policy {reference!r}: no file {str(path)!r}")
        key = f"_policy_file_{abs(hash(str(path)))}"
        module = sys.modules.get(key)
        if module is None:
            spec = importlib.util.spec_from_file_location(key, path)
            module = importlib.util.module_from_spec(spec)
            try:
                spec.loader.exec_module(module)
            except Exception as err:
                raise ValueError(f"policy {reference!r}: {path.name} fails to import: "
                                 f"{type(err).__name__}: {err}") from err
            sys.modules[key] = module
    else:
        for directory in search:
            if directory not in sys.path:
                sys.path.append(directory)
        try:
            module = importlib.import_module(target)
        except ModuleNotFoundError as err:
            if err.name is not None and target.startswith(err.name):
                raise ValueError(f"policy {reference!r}: no module {target!r} (is it on "
                                 f"the Python path? path/to/file.py:Class names a file)") \
                    from None
            raise ValueError(f"policy {reference!r}: module {target!r} fails to import: "
                             f"{err}") from err
        except Exception as err:
            raise ValueError(f"policy {reference!r}: module {target!r} fails to import: "
                             f"{type(err).__name__}: {err}") from err
    cls = getattr(module, name, None)
    if cls is None:
        raise ValueError(f"policy {reference!r}: {target} has no {name!r}")
    missing = [m for m in ("predict", "reset") if not callable(getattr(cls, m, None))]
    if missing:
        raise ValueError(f"policy {reference!r}: {name} has no {' and no '.join(missing)}; a "
                         f"policy has predict(obs, deterministic=True) -> (action, state) and "
                         f"reset(seed) (agents.policy.Policy)")
    return cls


def check_reference(reference: str) -> str:
    """``reference``, after importing the class it names (the errors of
    :func:`policy_class`)."""
    policy_class(reference)
    return reference


def make_policy(reference: str, env, seed: int = 0, *, search: list[str] | tuple = (),
                **kwargs) -> Policy:
    """The policy ``reference`` names, made for ``env`` as ``Class(env,
    seed=seed, **kwargs)`` (the reference's own arguments, then
    ``kwargs``).

    Raises
    ------
    ValueError
        The errors of :func:`policy_class`, or a class that cannot be made so.
    """
    cls = policy_class(reference, search)
    _, _, own = parse_reference(reference)
    try:
        return cls(env, seed=seed, **{**own, **kwargs})
    except TypeError as err:
        raise ValueError(f"policy {reference!r}: a policy class is made as "
                         f"{cls.__name__}(env, seed=seed, **kwargs): {err}") from err
