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
