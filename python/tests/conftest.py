"""Shared fixtures of the Python package's tests: the repository, the CLI to compare with.

The tests run against the installed wheel (``import posecov``), never against the source
folder: CI (``.ci/run``) builds the wheel, installs it into its pinned virtualenv and runs
``pytest python/tests``. Comparisons with the command line need the ``posecov`` binary:
``$POSECOV`` (CI passes the one ``cargo test`` built), else ``$CARGO_TARGET_DIR/debug/posecov``.
"""

import json
import os
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]


def cli_path():
    """The posecov binary, or None."""
    given = os.environ.get("POSECOV")
    if given:
        return given
    target = os.environ.get("CARGO_TARGET_DIR", str(ROOT / "target"))
    candidate = Path(target) / "debug" / "posecov"
    return str(candidate) if candidate.exists() else None


def comparable(report):
    """A report without what changes from run to run: a pose graph's wall-clock timings
    (`optimized.seconds`, docs/report.schema.json). Everything else is deterministic."""
    report = json.loads(json.dumps(report))
    if isinstance(report.get("optimized"), dict):
        report["optimized"].pop("seconds", None)
    return report


@pytest.fixture(scope="session")
def root():
    return ROOT


@pytest.fixture(scope="session")
def cli():
    """Runs the CLI: cli(*args) -> (exit code, stdout, stderr). In CI a missing binary fails."""
    path = cli_path()
    if path is None:
        if os.environ.get("CI"):
            pytest.fail("no posecov binary: set $POSECOV")
        pytest.skip("no posecov binary (set $POSECOV) to compare with")

    def run(*args):
        out = subprocess.run([path, *map(str, args)], capture_output=True, text=True, timeout=600)
        return out.returncode, out.stdout, out.stderr

    return run


@pytest.fixture(scope="session")
def cli_json(cli):
    """The parsed stdout of `posecov report ARGS --json`."""

    def run(*args):
        code, out, err = cli("report", *args, "--json")
        return code, json.loads(out), err

    return run
