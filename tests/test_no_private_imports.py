"""No module imports another module's private names (``from .x import
_name``): what one module shares with another is public, named without a
leading underscore, so that a change inside a module cannot break another
one unseen. Importing a private *module* of a package (``physics._jit_cache``)
is allowed: the underscore there marks it as not part of the package's API."""
import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
PACKAGES = ("physics", "iceenvs", "agents", "seaice_gym", "benchmarks")


def _module_path(source: Path, node: ast.ImportFrom, root: Path) -> Path | None:
    """The folder or file a ``from … import`` names, or None outside the project."""
    if node.level:
        base = source.parent
        for _ in range(node.level - 1):
            base = base.parent
    else:
        if (node.module or "").split(".")[0] not in PACKAGES:
            return None
        base = root
    for part in (node.module or "").split(".") if node.module else ():
        base = base / part
    return base


def private_imports(source: Path, root: Path = ROOT) -> list[str]:
    found = []
    for node in ast.walk(ast.parse(source.read_text(encoding="utf-8"))):
        if not isinstance(node, ast.ImportFrom) or node.module == "__future__":
            continue
        target = _module_path(source, node, root)
        if target is None:
            continue
        for alias in node.names:
            name = alias.name
            if not name.startswith("_") or name.startswith("__"):
                continue
            if (target / f"{name}.py").is_file() or (target / name).is_dir():
                continue                                   # a private module
            found.append(f"{source.relative_to(root).as_posix()}:{node.lineno} imports {name}")
    return found


def test_no_module_imports_another_modules_private_names():
    sources = [p for pkg in PACKAGES for p in (ROOT / pkg).rglob("*.py")]
    assert len(sources) > 100
    found = [hit for p in sources for hit in private_imports(p)]
    assert not found, "\n".join(found)


def test_the_check_finds_a_private_name(tmp_path):
    """It would catch what it is meant to, and only that."""
    package = tmp_path / "physics"
    package.mkdir()
    (package / "kernels.py").write_text("_OK = 0\npublic = 1\n")
    (package / "_cache.py").write_text("")
    user = package / "user.py"
    user.write_text("from .kernels import _OK, public\nfrom . import _cache\n"
                    "from physics.kernels import _OK as ok\nfrom os import _exit\n")
    assert private_imports(user, tmp_path) == ["physics/user.py:1 imports _OK",
                                               "physics/user.py:3 imports _OK"]


# -- attribute access -----------------------------------------------------------
#: private names of Python's own that other modules may use (named tuples, os)
PYTHON_PRIVATE = {"_replace", "_fields", "_asdict", "_make", "_field_defaults", "_exit",
                  # Gymnasium's builder of a vector info, which the vector
                  # environments' infos follow to the letter
                  "_add_info"}

#: the reach-ins that remain, by module; the list may only shrink
KNOWN_REACH_INS: dict[str, set[str]] = {}


#: benchmarks that time a private part of an environment's step on purpose
TIMED_PRIVATE = {"benchmarks/bench_sensors.py": {"_image"}}


def _own_private_names(tree: ast.AST) -> set[str]:
    """The private names a module defines: its functions, classes and
    module-level names, and the attributes it assigns on ``self`` or
    ``cls``."""
    names = set()
    for node in ast.walk(tree):
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
            names.add(node.name)
        elif isinstance(node, ast.Attribute) and isinstance(node.ctx, ast.Store) \
                and isinstance(node.value, ast.Name) and node.value.id in ("self", "cls"):
            names.add(node.attr)
        elif isinstance(node, ast.Assign):
            names.update(t.id for t in node.targets if isinstance(t, ast.Name))
        elif isinstance(node, ast.AnnAssign) and isinstance(node.target, ast.Name):
            names.add(node.target.id)
    return {n for n in names if n.startswith("_")}


def private_reach_ins(source: Path, root: Path = ROOT) -> dict[str, set[str]]:
    """The private attributes (``obj._name``, obj not ``self`` or ``cls``)
    that ``source`` reads or writes without defining them itself: another
    module's private state. {module: names}, empty when there is none."""
    tree = ast.parse(source.read_text(encoding="utf-8"))
    own = _own_private_names(tree) | PYTHON_PRIVATE
    found = set()
    for node in ast.walk(tree):
        if (isinstance(node, ast.Attribute) and node.attr.startswith("_")
                and not node.attr.startswith("__") and node.attr not in own
                and not (isinstance(node.value, ast.Name) and node.value.id in ("self", "cls"))):
            found.add(node.attr)
    return {source.relative_to(root).as_posix(): found} if found else {}


def test_no_module_reaches_into_another_modules_private_attributes():
    sources = [p for pkg in PACKAGES for p in (ROOT / pkg).rglob("*.py")]
    found = {}
    for p in sources:
        found.update(private_reach_ins(p))
    allowed = {m: KNOWN_REACH_INS.get(m, set()) | TIMED_PRIVATE.get(m, set()) for m in found}
    new = {m: names - allowed[m] for m, names in found.items()}
    new = {m: sorted(n) for m, n in new.items() if n}
    assert not new, f"private attributes of another module used in: {new}"
    gone = {m: sorted(names - found.get(m, set())) for m, names in KNOWN_REACH_INS.items()}
    gone = {m: n for m, n in gone.items() if n}
    assert not gone, f"reach-ins fixed: take them off KNOWN_REACH_INS: {gone}"


def test_the_check_finds_a_reach_in(tmp_path):
    """A planted reach-in is found; the module's own members, named tuples'
    API and ``self``/``cls`` are not."""
    package = tmp_path / "iceenvs"
    package.mkdir()
    user = package / "user.py"
    user.write_text("class A:\n    def __init__(self):\n        self._mine = 1\n"
                    "    def same(self, other):\n        return other._mine\n"
                    "def f(env, t):\n    env._steps += 1\n    return t._replace(x=1), self_ish._x\n")
    assert private_reach_ins(user, tmp_path) == {"iceenvs/user.py": {"_steps", "_x"}}
