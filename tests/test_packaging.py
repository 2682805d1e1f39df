"""The package declares every library it needs at run time.

A `pip install sphdvi` (without the test extra) must run every case: an import that only the test
extra happens to pull in (scipy came with clarabel) works in CI and fails for users.
"""
import ast
import re
import sys
import tomllib
from importlib.metadata import packages_distributions
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
PACKAGE = REPO / "sphdvi"


def _project() -> dict:
    return tomllib.loads((REPO / "pyproject.toml").read_text())["project"]


def _names(requirements) -> set:
    """Distribution names of requirement strings, normalised (PEP 503)."""
    return {_normalise(re.split(r"[\s<>=!~;\[]", d, maxsplit=1)[0]) for d in requirements}


def _declared_distributions() -> set:
    return _names(_project()["dependencies"])


def _optional_feature_distributions() -> set:
    """The extras a user installs for a feature (not the test extra)."""
    extras = _project().get("optional-dependencies", {})
    return _names(r for name, reqs in extras.items() if name != "test" for r in reqs)


def _normalise(name: str) -> str:
    return re.sub(r"[-_.]+", "-", name).lower()


def _guarded_imports(tree) -> set:
    """Import nodes inside a ``try`` that catches ImportError (an optional feature's import)."""
    guarded = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Try) and any(
                isinstance(h.type, ast.Name) and h.type.id in ("ImportError", "ModuleNotFoundError")
                for h in node.handlers):
            guarded |= {id(n) for stmt in node.body for n in ast.walk(stmt)}
    return guarded


def _imported_top_level_modules() -> dict:
    """Absolute imports of the package's source: top-level module -> (the first file importing
    it, whether every import of it is guarded by an ImportError handler)."""
    found = {}
    for path in sorted(PACKAGE.rglob("*.py")):
        tree = ast.parse(path.read_text(), filename=str(path))
        guarded = _guarded_imports(tree)
        for node in ast.walk(tree):
            if isinstance(node, ast.Import):
                names = [a.name for a in node.names]
            elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
                names = [node.module]
            else:
                continue
            for name in names:
                where, all_guarded = found.get(name.split(".")[0], (path.relative_to(REPO), True))
                found[name.split(".")[0]] = (where, all_guarded and id(node) in guarded)
    return found


def test_every_third_party_import_of_the_package_is_a_declared_dependency():
    """Optional features (an extra such as `plot`) may import their library only behind an
    ImportError handler, which tells the user what to install."""
    declared, optional = _declared_distributions(), _optional_feature_distributions()
    dists = packages_distributions()
    missing = []
    for module, (where, guarded) in _imported_top_level_modules().items():
        if module in sys.stdlib_module_names or module == "sphdvi":
            continue
        provided_by = {_normalise(d) for d in dists.get(module, [module])}
        if not provided_by & (declared | (optional if guarded else set())):
            missing.append(f"{module} (imported by {where})")
    assert not missing, f"imported but not in pyproject's dependencies: {missing}"


def test_numba_linear_algebra_has_scipy_declared():
    """numba compiles np.linalg (eigh, norm, ...) and np.dot against scipy's BLAS/LAPACK; without
    scipy the first call fails with 'scipy 0.16+ is required for linear algebra'."""
    users = [p.relative_to(REPO) for p in PACKAGE.rglob("*.py")
             if "numba" in (text := p.read_text()) and re.search(r"np\.linalg\.|np\.dot\(", text)]
    assert users, "no numba module uses np.linalg: drop this test"
    assert "scipy" in _declared_distributions(), f"{users} use numba's linear algebra"
