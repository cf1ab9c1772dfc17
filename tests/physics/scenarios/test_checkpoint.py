"""The checkpoint format: what it writes, what it restores (values, aliases,
views, generators, the physics package's objects), what it refuses to write
and which files it refuses to read."""
from __future__ import annotations

import collections
import dataclasses
import enum
import pickle
import sys
import types
import zipfile

import numpy as np
import pytest

pytest.importorskip("yaml")

from physics.scenarios import checkpoint as ck
from physics.scenarios.recorder import Recorder, checkpoint_files

# Classes standing for the physics package's own (engines, bundles, statuses):
# they are registered below as the module physics._checkpoint_test_types.
MODULE = "physics._checkpoint_test_types"


class Status(enum.IntEnum):
    RUNNING = 0
    STOPPED = 3


Bundle = collections.namedtuple("Bundle", ["pos", "n"], module=MODULE)


@dataclasses.dataclass(frozen=True)
class Params:
    k: float
    name: str


class Engine:
    def __init__(self):
        raise AssertionError("a checkpoint never calls the constructor")


class Slotted:
    __slots__ = ("a", "b")


for _cls in (Status, Params, Engine, Slotted):
    _cls.__module__ = MODULE


@pytest.fixture(autouse=True)
def fake_physics_module(monkeypatch):
    mod = types.ModuleType(MODULE)
    for cls in (Status, Bundle, Params, Engine, Slotted):
        setattr(mod, cls.__name__, cls)
    monkeypatch.setitem(sys.modules, MODULE, mod)


def _round_trip(tmp_path, value):
    path = tmp_path / "state.ckpt"
    ck.save(path, value, meta={"fraction": 0.25})
    assert ck.read_meta(path) == {"fraction": 0.25}
    return ck.load(path)


def _engine():
    eng = Engine.__new__(Engine)
    eng._pos = np.arange(12.0).reshape(6, 2)
    eng.status = Status.STOPPED
    eng.bundle = Bundle(eng._pos, 6)
    eng.params = Params(2.5, "hertz")
    eng.rng = np.random.default_rng(7)
    eng.rng.normal(size=3)
    eng.me = eng                                   # a cycle
    return eng


def test_plain_values_round_trip_exactly(tmp_path):
    value = {
        "none": None, "flags": [True, False], "big": 2 ** 100, "neg": -3,
        "floats": [0.1, -0.0, 1e-310, 1.7976931348623157e308, float("inf"), float("nan"),
                   2 / 3],
        "text": "a: b\n- c", "tuple": (1, (2.5, "x")), "int_keys": {1: "a", (2, 3): [4]},
        "arrays": [np.arange(5, dtype=np.int32), np.zeros((0, 3)), np.array([1 + 2j]),
                   np.asfortranarray(np.arange(6.0).reshape(2, 3)), np.array([True, False]),
                   np.array(["ab", "c"]), np.zeros(3, dtype=[("x", "f8"), ("i", "i4")])],
        "scalars": [np.float32(1.5), np.int64(-7), np.bool_(True), np.float64(0.1)],
    }
    back = _round_trip(tmp_path, value)
    assert back["none"] is None and back["flags"] == [True, False] and back["big"] == 2 ** 100
    assert back["neg"] == -3 and back["text"] == value["text"]
    assert back["tuple"] == (1, (2.5, "x")) and back["int_keys"] == {1: "a", (2, 3): [4]}
    assert [f.hex() for f in back["floats"]] == [f.hex() for f in value["floats"]]
    for a, b in zip(back["arrays"], value["arrays"]):
        assert a.dtype == b.dtype and a.shape == b.shape and a.flags.f_contiguous == \
            b.flags.f_contiguous
        np.testing.assert_array_equal(a, b)
    for a, b in zip(back["scalars"], value["scalars"]):
        assert type(a) is type(b) and a == b


def test_aliases_views_and_read_only_arrays_survive(tmp_path):
    base = np.arange(20.0)
    shared = [1, 2]
    frozen = np.ones(3)
    frozen.flags.writeable = False
    outside = np.frombuffer(bytearray(80))          # memory held by another object
    value = {"a": base, "b": base, "head": base[:4], "odd": base[1::2], "back": base[::-1],
             "grid": base.reshape(4, 5)[:, 1:3], "l1": shared, "l2": shared, "frozen": frozen,
             "outside": outside, "outside_view": outside[2:5]}
    back = _round_trip(tmp_path, value)
    assert np.shares_memory(back["outside"], back["outside_view"])
    assert back["a"] is back["b"] and back["l1"] is back["l2"]
    for key in ("head", "odd", "back", "grid"):
        np.testing.assert_array_equal(back[key], value[key], err_msg=key)
        assert np.shares_memory(back[key], back["a"]), key
    back["a"][1] = -1.0                                  # writes reach every view
    assert back["odd"][0] == -1.0 and back["grid"][0, 0] == -1.0 and back["back"][-2] == -1.0
    assert not back["frozen"].flags.writeable


def test_generators_continue_their_streams(tmp_path):
    rng = np.random.default_rng(123)
    rng.random(5)
    mt = np.random.Generator(np.random.MT19937(4))
    back = _round_trip(tmp_path, {"rng": rng, "same": rng, "mt": mt})
    assert back["rng"] is back["same"]
    np.testing.assert_array_equal(back["rng"].normal(size=50), rng.normal(size=50))
    np.testing.assert_array_equal(back["mt"].integers(0, 1 << 40, size=50),
                                  mt.integers(0, 1 << 40, size=50))


def test_objects_of_the_physics_package_are_rebuilt_without_their_constructor(tmp_path):
    eng = _engine()
    slotted = Slotted()
    slotted.a = np.arange(3)
    back = _round_trip(tmp_path, {"sim": eng, "slotted": slotted})
    sim = back["sim"]
    assert type(sim) is Engine and sim.me is sim
    assert sim.status is Status.STOPPED
    assert type(sim.bundle) is Bundle and sim.bundle.n == 6 and sim.bundle.pos is sim._pos
    assert sim.params == Params(2.5, "hertz")
    np.testing.assert_array_equal(sim.rng.random(4), eng.rng.random(4))
    assert type(back["slotted"]) is Slotted and not hasattr(back["slotted"], "b")
    np.testing.assert_array_equal(back["slotted"].a, [0, 1, 2])


class Outsider:
    """A class of the tests, not of the physics package."""


@pytest.mark.parametrize("bad, where, what", [
    (lambda: None, "state['sim'].callback", "function"),
    (Outsider(), "state['sim'].callback", "Outsider"),
    (np.array([object()]), "state['sim'].callback", "dtype object"),
    ({1, 2}, "state['sim'].callback", "set"),
])
def test_what_cannot_be_written_is_named_before_anything_is_written(tmp_path, bad, where, what):
    eng = _engine()
    eng.callback = bad
    path = tmp_path / "x.ckpt"
    with pytest.raises(TypeError, match="cannot checkpoint") as err:
        ck.save(path, {"state": {"sim": eng}})
    assert where in str(err.value) and what in str(err.value)
    assert not path.exists()


def _file(tmp_path, structure: str, arrays=()):
    path = tmp_path / "crafted.ckpt"
    with zipfile.ZipFile(path, "w") as zf:
        zf.writestr("structure.yaml", structure)
        for key, arr in arrays:
            with zf.open(key + ".npy", "w") as fh:
                np.lib.format.write_array(fh, arr)
    return path


def test_classes_are_only_looked_up_in_the_physics_package(tmp_path):
    head = f"format: seaice-gym checkpoint\nversion: {ck.VERSION}\nmeta: {{}}\ndata:\n"
    was_imported = "this" in sys.modules
    for name in ("this:Thing", "os:system", "builtins:dict", "physics.hertz:np.ndarray"):
        path = _file(tmp_path, head + f"  object: '{name}'\n")
        with pytest.raises(ck.CheckpointError, match="package's classes|does not exist"):
            ck.load(path)
    assert ("this" in sys.modules) == was_imported
    path = _file(tmp_path, head + f"  enum: '{MODULE}:Status'\n  value: 3\n")
    assert ck.load(path) is Status.STOPPED
    path = _file(tmp_path, head + "  list: &x [1]\n  other: *x\n")
    with pytest.raises(ck.CheckpointError, match="aliases"):
        ck.load(path)


def test_unreadable_files_say_why(tmp_path):
    good = tmp_path / "good.ckpt"
    ck.save(good, {"x": np.arange(1000.0)})
    data = good.read_bytes()
    cases = {"truncated": data[: len(data) // 2],
             "empty": b"",
             "pickle": pickle.dumps({"x": 1}),
             "text": b"hello"}
    flipped = bytearray(data)
    flipped[-2000] ^= 0xFF                      # inside the array's bytes
    cases["flipped"] = bytes(flipped)
    reasons = {"truncated": "damaged or truncated", "empty": "not a checkpoint archive",
               "pickle": "pickle file", "text": "not a checkpoint archive", "flipped": "damaged"}
    for name, content in cases.items():
        path = tmp_path / f"{name}.ckpt"
        path.write_bytes(content)
        with pytest.raises(ck.CheckpointError, match=reasons[name]):
            ck.load(path)
    other = _file(tmp_path, "format: seaice-gym checkpoint\nversion: 1\nmeta: {}\ndata: 1\n")
    with pytest.raises(ck.CheckpointError, match=f"format version 1; this version reads {ck.VERSION}"):
        ck.load(other)


def test_recorder_keeps_two_generations_and_falls_back(tmp_path):
    path = tmp_path / "job.ckpt"
    rec = Recorder(path, 0.0)
    for step in range(3):
        rec.record(float(step), p=step)
        rec.checkpoint({"step": step})
    newest, previous = checkpoint_files(path)
    assert previous.name == "job.previous.ckpt"
    assert Recorder(path).restore() == {"step": 2}
    newest.write_bytes(newest.read_bytes()[:100])              # cut short
    messages = []
    rec = Recorder(path, log=messages.append)
    assert rec.restore() == {"step": 1} and len(rec.rows) == 2
    assert len(messages) == 1 and str(newest) in messages[0] and str(previous) in messages[0]
    assert "damaged or truncated" in messages[0] and rec.notes == messages
    rec.checkpoint({"step": 5}, force=True)
    # the damaged file was replaced, the good one kept as the previous
    assert Recorder(path).restore() == {"step": 5}
    newest.write_bytes(b"junk")
    assert Recorder(path, log=messages.append).restore() == {"step": 1}
    previous.write_bytes(b"junk")
    fresh = Recorder(path, log=messages.append)
    assert fresh.restore() is None and not fresh.rows
    assert "starts again from the beginning" in messages[-1]
