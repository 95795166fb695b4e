"""The stubs (_posecov.pyi) name exactly what the native module has."""

import ast
from pathlib import Path

import posecov
from posecov import _posecov


def stub_tree():
    return ast.parse((Path(posecov.__file__).parent / "_posecov.pyi").read_text())


def test_stub_names_match_the_module():
    tree = stub_tree()
    stubbed = {n.name for n in tree.body if isinstance(n, (ast.FunctionDef, ast.ClassDef))}
    stubbed |= {t.target.id for t in tree.body if isinstance(t, ast.AnnAssign)}
    stubbed -= {"_Group"}
    public = {n for n in dir(_posecov) if not n.startswith("_")}
    assert stubbed == public


def test_stub_methods_exist():
    tree = stub_tree()
    classes = {n.name: n for n in tree.body if isinstance(n, ast.ClassDef)}
    group = {f.name for f in classes["_Group"].body if isinstance(f, ast.FunctionDef)}
    for name in ("SO2", "SO3", "SE2", "SE3"):
        own = {f.name for f in classes[name].body if isinstance(f, ast.FunctionDef)}
        cls = getattr(_posecov, name)
        assert {m for m in dir(cls) if not m.startswith("_")} == group | own | {"DOF", "ORDER"}
    pose = {f.name for f in classes["UncertainPose"].body if isinstance(f, ast.FunctionDef)} - {"__init__"}
    assert {m for m in dir(_posecov.UncertainPose) if not m.startswith("_")} == pose


def test_every_public_callable_has_a_docstring_with_an_example():
    for name in ("SO2", "SO3", "SE2", "SE3", "UncertainPose"):
        cls = getattr(_posecov, name)
        assert ">>>" in cls.__doc__, name
        for m in dir(cls):
            if m.startswith("_") or m in ("DOF", "ORDER", "group", "mean", "cov", "side", "order"):
                continue
            assert ">>>" in (getattr(cls, m).__doc__ or ""), f"{name}.{m}"
    for f in (posecov.report, posecov.check, posecov.figure, posecov.figure_svg, posecov.examples, posecov.expand):
        assert ">>>" in f.__doc__, f.__name__


def test_the_installed_wheel_is_tested(root):
    """.ci/python-venv installs the wheel and runs these tests against it (it sets
    POSECOV_TESTING_WHEEL), not against python/posecov: the package is imported from the
    virtualenv's site-packages, with the native module inside it."""
    import os

    import pytest

    if not os.environ.get("POSECOV_TESTING_WHEEL"):
        pytest.skip("not run by .ci/python-venv (a `maturin develop` build may be under test)")
    package = Path(posecov.__file__).resolve().parent
    assert root / "python" not in package.parents
    assert "site-packages" in package.parts
    assert Path(_posecov.__file__).resolve().parent == package
