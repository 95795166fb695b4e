"""Every example in the package's docstrings runs (the Python wrappers and the native
classes' docstrings, written in python/src/*.rs)."""

import doctest

import numpy as np
import pytest

import posecov
import posecov.notebook
from posecov import _posecov

OBJECTS = [posecov, posecov.notebook] + [getattr(_posecov, n) for n in ("SO2", "SO3", "SE2", "SE3", "UncertainPose")]


@pytest.mark.parametrize("obj", OBJECTS, ids=lambda o: getattr(o, "__name__", str(o)))
def test_docstring_examples(obj):
    finder = doctest.DocTestFinder(exclude_empty=True)
    runner = doctest.DocTestRunner(optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE)
    globs = None if obj in (posecov, posecov.notebook) else {"posecov": posecov, "np": np}
    tests = finder.find(obj, getattr(obj, "__name__", "posecov"), globs=globs)
    if isinstance(obj, type):
        # Methods of a native class: DocTestFinder does not descend into them.
        for name in dir(obj):
            member = getattr(obj, name)
            doc = getattr(member, "__doc__", None)
            if name.startswith("_") or not doc or ">>>" not in doc:
                continue
            tests.append(doctest.DocTestParser().get_doctest(doc, {"posecov": posecov, "np": np}, f"{obj.__name__}.{name}", None, 0))
    assert tests
    for test in tests:
        runner.run(test)
    assert runner.failures == 0
