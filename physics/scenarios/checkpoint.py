"""Checkpoint files that cannot run code when they are read.

A checkpoint is one ZIP archive in the layout of NumPy's ``.npz`` files: the
arrays of the saved state as ``.npy`` members, read back with
``numpy.lib.format.read_array(..., allow_pickle=False)`` (and readable with
``numpy.load(..., allow_pickle=False)``), and a member ``structure.yaml``,
read with PyYAML's safe loader, that describes how they fit together. Both can
be inspected with ordinary tools (``unzip -p FILE structure.yaml``).

Only these kinds of values are written:

* ``None``, ``bool``, ``int``, ``float``, ``str``, and ``list``, ``tuple`` and
  ``dict`` of them;
* NumPy arrays (not of dtype ``object``), with the views of one array
  restored as views of it, and NumPy scalars;
* :class:`numpy.random.Generator` and the bit generators of
  :mod:`numpy.random`, through their ``state``;
* enumerations, named tuples, dataclasses and plain objects whose classes
  are defined in the ``physics`` package (an object whose class defines
  ``__checkpoint_attrs__()`` is written with the attributes that method
  returns instead of its ``__dict__``). Such an object is rebuilt as
  ``cls.__new__(cls)`` followed by an update of its ``__dict__`` (and
  ``__slots__``): no constructor, ``__setstate__`` or ``__reduce__`` runs,
  and a class is only looked up by module and qualified name in modules of
  ``physics``.

A value referenced from several places (the same array, list or object) is
written once and restored as one object, so aliases survive a round trip.
Anything else raises a :class:`TypeError` naming its place in the saved
value (``state['sim']._forcing.wind`` for the entry ``state`` of a saved
dict) before anything is written. A file
that cannot be read (truncated, damaged, of another version, an older
checkpoint in pickle format, or naming a class outside ``physics``) raises
:class:`CheckpointError`.
"""
from __future__ import annotations

import enum
import functools
import importlib
import zipfile

import numpy as np

FORMAT = "seaice-gym checkpoint"
#: 3: the engines hold their per-floe arrays privately (``radii``, ``masses``,
#: ``frozen`` are read-only views), so a saved engine of version 2 cannot be resumed
VERSION = 3
STRUCTURE = "structure.yaml"
#: the package whose classes a checkpoint may hold
PACKAGE = "physics"

_PLAIN = (type(None), bool, int, float, str)


class CheckpointError(ValueError):
    """A checkpoint file that cannot be read; the message says why."""


@functools.cache
def _yaml():
    """(yaml, the writer's dumper, the reader's loader)."""
    import yaml

    class Dumper(yaml.SafeDumper):
        def ignore_aliases(self, data):
            return True

    class Loader(yaml.SafeLoader):
        # the writer never uses anchors; refusing aliases bounds the work a
        # crafted file can ask of the reader
        def compose_node(self, parent, index):
            if self.check_event(yaml.AliasEvent):
                raise yaml.YAMLError("YAML aliases are not used in checkpoints")
            return super().compose_node(parent, index)
    return yaml, Dumper, Loader


def _class_name(cls: type) -> str:
    return f"{cls.__module__}:{cls.__qualname__}"


def _in_package(module: str) -> bool:
    return module == PACKAGE or module.startswith(PACKAGE + ".")


def _lookup_class(name: str) -> type:
    """The class ``module:qualname``, looked up only in modules of the
    ``physics`` package."""
    if not isinstance(name, str) or name.count(":") != 1:
        raise CheckpointError(f"bad class name {name!r}")
    module, qualname = name.split(":")
    if not _in_package(module) or "<locals>" in qualname:
        raise CheckpointError(f"class {name!r} is not one of the {PACKAGE} package's classes")
    obj = importlib.import_module(module)
    for part in qualname.split("."):
        obj = getattr(obj, part, None)
    if not isinstance(obj, type) or obj.__module__ != module:
        raise CheckpointError(f"class {name!r} does not exist (any more)")
    return obj


def _is_named_tuple(value) -> bool:
    return isinstance(value, tuple) and hasattr(type(value), "_fields")


def _slot_names(cls: type) -> list[str]:
    names = []
    for klass in cls.__mro__:
        slots = klass.__dict__.get("__slots__", ())
        for name in (slots,) if isinstance(slots, str) else slots:
            if name not in ("__dict__", "__weakref__") and name not in names:
                names.append(name)
    return names


# ---------------------------------------------------------------------------
# writing
# ---------------------------------------------------------------------------

class _Encoder:
    """Turns a value into a YAML-able tree of nodes plus named arrays."""

    def __init__(self):
        self.arrays: dict[str, np.ndarray] = {}
        self._memo: dict[int, tuple[int, dict, object]] = {}
        self._shared: set[int] = set()

    def _array_key(self, arr: np.ndarray) -> str:
        key = f"a{len(self.arrays)}"
        self.arrays[key] = arr
        return key

    def _remember(self, value, node: dict) -> dict:
        n = len(self._memo)
        node["id"] = n
        self._memo[id(value)] = (n, node, value)    # the value is kept alive: ids stay unique
        return node

    def finish(self) -> None:
        """Drop the ids that nothing refers to (they only clutter the YAML)."""
        for n, node, _ in self._memo.values():
            if n not in self._shared:
                del node["id"]

    def encode(self, value, path: str):
        if type(value) in _PLAIN:
            return value
        if id(value) in self._memo:
            n = self._memo[id(value)][0]
            self._shared.add(n)
            return {"ref": n}
        if type(value) is list:
            node = self._remember(value, {"list": []})
            node["list"] = [self.encode(v, f"{path}[{i}]") for i, v in enumerate(value)]
            return node
        if type(value) is dict:
            return self._dict(value, path)
        if type(value) is tuple:
            return {"tuple": [self.encode(v, f"{path}[{i}]") for i, v in enumerate(value)]}
        if isinstance(value, np.ndarray) and type(value) is np.ndarray:
            return self._array(value, path)
        if isinstance(value, np.generic):
            if value.dtype.hasobject:
                raise TypeError(f"cannot checkpoint {path}: a NumPy scalar of dtype object")
            return {"scalar": self._array_key(np.asarray(value))}
        if type(value) is np.random.Generator:
            node = self._remember(value, {"generator": None})
            node["generator"] = self.encode(value.bit_generator, f"{path}.bit_generator")
            return node
        if isinstance(value, np.random.BitGenerator):
            cls = type(value)
            if getattr(np.random, cls.__name__, None) is not cls:
                raise TypeError(f"cannot checkpoint {path}: bit generator {_class_name(cls)} "
                                f"is not one of numpy.random's")
            node = self._remember(value, {"bit_generator": cls.__name__, "state": None})
            node["state"] = self.encode(value.state, f"{path}.state")
            return node
        return self._instance(value, path)

    def _dict(self, value: dict, path: str) -> dict:
        # the entries of the top-level dict are named by their keys alone
        def item(k):
            return f"{path}[{k!r}]" if path else str(k)
        if all(type(k) is str for k in value):
            node = self._remember(value, {"dict": {}})
            node["dict"] = {k: self.encode(v, item(k)) for k, v in value.items()}
        else:
            node = self._remember(value, {"pairs": []})
            node["pairs"] = [[self.encode(k, f"{path}.keys()[{i}]"), self.encode(v, item(k))]
                             for i, (k, v) in enumerate(value.items())]
        return node

    def _array(self, arr: np.ndarray, path: str) -> dict:
        if arr.dtype.hasobject:
            raise TypeError(f"cannot checkpoint {path}: an array of dtype object")
        root = arr.base            # NumPy keeps it the array that holds the memory
        if (isinstance(root, np.ndarray) and type(root) is np.ndarray
                and not isinstance(root.base, np.ndarray)
                and (root.flags.c_contiguous or root.flags.f_contiguous)
                and np.dtype(arr.dtype.str) == arr.dtype):
            # a view: written as its place in the array it looks into
            node = self._remember(arr, {"view": None})
            node.update(view=self.encode(root, f"{path}.base"),
                        offset=int(arr.__array_interface__["data"][0]
                                   - root.__array_interface__["data"][0]),
                        shape=list(arr.shape), strides=list(arr.strides), dtype=arr.dtype.str)
        else:
            node = self._remember(arr, {"array": self._array_key(arr)})
        if not arr.flags.writeable:
            node["writeable"] = False
        return node

    def _instance(self, value, path: str) -> dict:
        cls = type(value)
        if not _in_package(cls.__module__) or "<locals>" in cls.__qualname__:
            raise TypeError(f"cannot checkpoint {path}: a {cls.__module__}.{cls.__qualname__} "
                            f"(checkpoints hold None, bool, int, float, str, list, tuple, dict, "
                            f"NumPy arrays, scalars and generators, and objects of classes "
                            f"defined in the {PACKAGE} package)")
        name = _class_name(cls)
        if isinstance(value, enum.Enum):
            return {"enum": name, "value": self.encode(value.value, f"{path}.value")}
        if _is_named_tuple(value):
            return {"namedtuple": name,
                    "items": [self.encode(v, f"{path}.{f}") for f, v in zip(cls._fields, value)]}
        builtin = next(b for b in cls.__mro__ if b.__module__ == "builtins")
        if builtin is not object or isinstance(value, type):
            raise TypeError(f"cannot checkpoint {path}: {name} derives from "
                            f"{builtin.__name__}, which is not written")
        node = self._remember(value, {"object": name})
        if hasattr(value, "__dict__"):
            # an object whose attributes include a live handle (a LAMMPS
            # instance) gives what stands for them through __checkpoint_attrs__
            hook = getattr(cls, "__checkpoint_attrs__", None)
            attrs = hook(value) if hook is not None else vars(value)
            node["attrs"] = {k: self.encode(v, f"{path}.{k}") for k, v in attrs.items()}
        slots = {k: self.encode(getattr(value, k), f"{path}.{k}")
                 for k in _slot_names(cls) if hasattr(value, k)}
        if slots:
            node["slots"] = slots
        return node


def dumps(value, meta: dict | None = None) -> tuple[str, dict[str, np.ndarray]]:
    """(YAML text, arrays) describing ``value``; raises :class:`TypeError`
    naming the place of the first value that cannot be written."""
    yaml, dumper, _ = _yaml()
    enc = _Encoder()
    tree = enc.encode(value, "" if type(value) is dict else "value")
    enc.finish()
    doc = {"format": FORMAT, "version": VERSION, "meta": dict(meta or {}), "data": tree}
    return yaml.dump(doc, Dumper=dumper, sort_keys=False, width=100), enc.arrays


def save(path, value, meta: dict | None = None) -> None:
    """Write ``value`` to the checkpoint file ``path`` (not atomically: see
    :func:`physics.scenarios.recorder.atomic_write`). ``meta`` (a dict of
    plain values) is stored beside it and read back by :func:`read_meta`
    without the arrays."""
    text, arrays = dumps(value, meta)
    with zipfile.ZipFile(path, "w", zipfile.ZIP_STORED, allowZip64=True) as zf:
        zf.writestr(STRUCTURE, text)
        for key, arr in arrays.items():
            with zf.open(key + ".npy", "w", force_zip64=True) as fh:
                np.lib.format.write_array(fh, arr, allow_pickle=False)


# ---------------------------------------------------------------------------
# reading
# ---------------------------------------------------------------------------

_TAGS = ("list", "dict", "pairs", "tuple", "array", "view", "scalar", "generator",
         "bit_generator", "enum", "namedtuple", "object", "ref")


class _Decoder:
    def __init__(self, archive: zipfile.ZipFile):
        self.archive = archive
        self._memo: dict[int, object] = {}

    def _remember(self, node: dict, value):
        if "id" in node:
            self._memo[node["id"]] = value
        return value

    def _stored(self, key):
        if not isinstance(key, str):
            raise CheckpointError(f"bad array name {key!r}")
        with self.archive.open(key + ".npy") as fh:
            return np.lib.format.read_array(fh, allow_pickle=False)

    def decode(self, node):
        if type(node) in _PLAIN:
            return node
        if type(node) is not dict:
            raise CheckpointError(f"unexpected {type(node).__name__} in the structure")
        tags = [t for t in _TAGS if t in node]
        if len(tags) != 1:
            raise CheckpointError(f"bad node with keys {sorted(node)}")
        return getattr(self, "_" + tags[0])(node)

    def _ref(self, node):
        if node["ref"] not in self._memo:
            raise CheckpointError(f"reference to unknown object {node['ref']!r}")
        return self._memo[node["ref"]]

    def _list(self, node):
        out = self._remember(node, [])
        out.extend(self.decode(v) for v in node["list"])
        return out

    def _dict(self, node):
        out = self._remember(node, {})
        out.update((k, self.decode(v)) for k, v in node["dict"].items())
        return out

    def _pairs(self, node):
        out = self._remember(node, {})
        out.update((self.decode(k), self.decode(v)) for k, v in node["pairs"])
        return out

    def _tuple(self, node):
        return tuple(self.decode(v) for v in node["tuple"])

    def _with_flag(self, node, arr):
        if node.get("writeable", True) is False:
            arr.flags.writeable = False
        return self._remember(node, arr)

    def _array(self, node):
        return self._with_flag(node, self._stored(node["array"]))

    def _view(self, node):
        root = self.decode(node["view"])
        if not isinstance(root, np.ndarray):
            raise CheckpointError("a view of something that is not an array")
        raw = root.reshape(-1, order="A").view(np.uint8)     # the root's bytes, no copy
        view = np.ndarray(shape=tuple(int(s) for s in node["shape"]),
                          dtype=np.dtype(str(node["dtype"])), buffer=raw,
                          offset=int(node["offset"]),
                          strides=tuple(int(s) for s in node["strides"]))
        return self._with_flag(node, view)

    def _scalar(self, node):
        arr = self._stored(node["scalar"])
        if arr.ndim != 0:
            raise CheckpointError("a scalar stored as an array with dimensions")
        return arr[()]

    def _generator(self, node):
        # the bit generator's node comes first: its id may be referred to later
        return self._remember(node, np.random.Generator(self.decode(node["generator"])))

    def _bit_generator(self, node):
        cls = getattr(np.random, str(node["bit_generator"]), None)
        if not (isinstance(cls, type) and issubclass(cls, np.random.BitGenerator)):
            raise CheckpointError(f"unknown bit generator {node['bit_generator']!r}")
        bg = self._remember(node, cls())
        bg.state = self.decode(node["state"])
        return bg

    def _enum(self, node):
        cls = _lookup_class(node["enum"])
        if not issubclass(cls, enum.Enum):
            raise CheckpointError(f"{node['enum']} is not an enumeration")
        return cls(self.decode(node["value"]))

    def _namedtuple(self, node):
        cls = _lookup_class(node["namedtuple"])
        if not (issubclass(cls, tuple) and hasattr(cls, "_fields")):
            raise CheckpointError(f"{node['namedtuple']} is not a named tuple")
        items = [self.decode(v) for v in node["items"]]
        if len(items) != len(cls._fields):
            raise CheckpointError(f"{node['namedtuple']} has {len(cls._fields)} fields, the "
                                  f"checkpoint {len(items)}")
        return tuple.__new__(cls, items)

    def _object(self, node):
        cls = _lookup_class(node["object"])
        if any(b.__module__ == "builtins" and b is not object for b in cls.__mro__) or \
                issubclass(cls, (enum.Enum, type)):
            raise CheckpointError(f"{node['object']} is not a plain class")
        obj = self._remember(node, cls.__new__(cls))
        attrs = {str(k): self.decode(v) for k, v in (node.get("attrs") or {}).items()}
        if attrs:
            obj.__dict__.update(attrs)
        for k, v in (node.get("slots") or {}).items():
            if k not in _slot_names(cls):
                raise CheckpointError(f"{node['object']} has no slot {k!r}")
            object.__setattr__(obj, k, self.decode(v))
        return obj


def _open(path) -> tuple[zipfile.ZipFile, dict]:
    """The open archive and its parsed structure; :class:`CheckpointError`
    if it is not a readable checkpoint."""
    yaml, _, loader = _yaml()
    try:
        with open(path, "rb") as fh:
            head = fh.read(4)
    except OSError as exc:
        raise CheckpointError(f"it cannot be opened ({exc})") from None
    if head[:1] == b"\x80":
        raise CheckpointError("it is a pickle file, the format of earlier versions, which is "
                              "never loaded because reading a pickle can run code")
    if head != b"PK\x03\x04":
        raise CheckpointError("it is not a checkpoint archive (damaged or of another kind)")
    try:
        zf = zipfile.ZipFile(path)
    except (zipfile.BadZipFile, EOFError, OSError) as exc:
        raise CheckpointError(f"it is damaged or truncated ({exc})") from None
    try:
        try:
            doc = yaml.load(zf.read(STRUCTURE).decode("utf-8"), Loader=loader)
        except (zipfile.BadZipFile, KeyError, EOFError, OSError, UnicodeDecodeError,
                yaml.YAMLError) as exc:
            raise CheckpointError(f"it is damaged or truncated ({exc})") from None
        if not isinstance(doc, dict) or doc.get("format") != FORMAT:
            raise CheckpointError("it is not a checkpoint archive (damaged or of another kind)")
        if doc.get("version") != VERSION:
            raise CheckpointError(f"it was written in checkpoint format version "
                                  f"{doc.get('version')!r}; this version reads {VERSION}")
    except CheckpointError:
        zf.close()
        raise
    return zf, doc


def read_meta(path) -> dict:
    """The ``meta`` dict saved with the checkpoint, without reading the
    arrays."""
    zf, doc = _open(path)
    zf.close()
    return dict(doc.get("meta") or {})


def load(path):
    """The value saved in the checkpoint file ``path``; raises
    :class:`CheckpointError` (naming the reason) if it cannot be read."""
    zf, doc = _open(path)
    try:
        with zf:
            return _Decoder(zf).decode(doc.get("data"))
    except CheckpointError:
        raise
    except Exception as exc:  # noqa: BLE001  (anything a damaged file can raise)
        raise CheckpointError(f"it is damaged ({type(exc).__name__}: {exc})") from None


__all__ = ["CheckpointError", "dumps", "save", "load", "read_meta", "FORMAT", "VERSION"]
