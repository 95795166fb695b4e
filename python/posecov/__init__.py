"""posecov from Python: robot pose uncertainty on Lie groups, on NumPy arrays.

The package wraps posecov's Rust library (the native module ``posecov._posecov``, built
without the Rerun viewer):

* ``report(source, **overrides)`` -- the object ``posecov report SOURCE --json`` prints, for a
  bundled example name, a TOML scenario, a g2o / GTSAM pose graph or a robot log;
* ``check(source, allow=(), **overrides)`` -- what ``posecov check SOURCE`` finds;
* ``figure(source, path, **options)`` -- the SVG / PNG / PDF ``posecov figure`` writes, and
  ``Figure(source, **options)`` shown inline in IPython / Jupyter (SVG);
* the groups ``SO2``, ``SO3``, ``SE2``, ``SE3`` (exp, log, compose, inverse, between,
  adjoints, Jacobians) and ``UncertainPose`` (compose, invert, change of frame, first /
  second / fourth-order compounding, sigma points, seeded Monte Carlo).

Conventions (posecov's ``docs/CONVENTIONS.md``): tangent vectors are translation first --
SE(2) ``[rho_x, rho_y, theta]``, SE(3) ``[rho (3); theta (3)]``; a covariance is on the
**right** (body) side unless marked left: X = mu · Exp(eps), eps ~ N(0, Sigma); the left
(world) form is X = Exp(eps) · mu with Sigma_left = Ad_mu Sigma_right Ad_mu^T. Jacobians are
with respect to right perturbations. Matrices go in and out as ``numpy.ndarray``.

Every input posecov refuses raises ``PosecovError`` (a ``ValueError``) with the CLI's located
message; nothing crashes the interpreter.

>>> import posecov
>>> posecov.report("camera_on_robot")["schema_version"]
2
"""

from __future__ import annotations

import json as _json
import re as _re
from os import PathLike, fspath
from typing import Any, Dict, Iterable, List, Optional, Union

from . import _posecov
from ._posecov import (
    OVERRIDES,
    POSECOV_VERSION,
    REPORT_SCHEMA_VERSION,
    SE2,
    SE3,
    SO2,
    SO3,
    PosecovError,
    UncertainPose,
)

__version__ = POSECOV_VERSION

__all__ = [
    "OVERRIDES",
    "POSECOV_VERSION",
    "REPORT_SCHEMA_VERSION",
    "SE2",
    "SE3",
    "SO2",
    "SO3",
    "Figure",
    "PosecovError",
    "UncertainPose",
    "check",
    "examples",
    "expand",
    "figure",
    "figure_svg",
    "report",
]


def report(source: Union[str, PathLike], **overrides: Any) -> Dict[str, Any]:
    """The report of one input: the object ``posecov report SOURCE --json`` prints.

    ``source`` is a bundled example's name (``posecov.examples()``), a TOML scenario, a
    g2o / GTSAM / TORO pose graph, or a robot log (ROS 1 ``.bag``, ``.mcap``, ROS 2 ``.db3``
    or bag directory). Keyword arguments are the CLI's flags with ``_`` for ``-``: ``seed``,
    ``samples``, ``confidence``, ``block_samples``, ``topic`` (a string or a list),
    ``every``, ``ros_reading`` ("tf2" or "body"), ``reference``, ``align``,
    ``graph_reading`` ("g2o" or "gtsam"), ``optimizer`` ("lm" or "gn"), ``joint`` ((A, B)
    or a list of pairs). The same ``schema_version`` as the CLI (``REPORT_SCHEMA_VERSION``).

    Raises ``PosecovError`` with the CLI's message (``exit_code``, ``details``) when the
    input is refused: an unknown name, a scenario error at file:line:column, a damaged log.

    >>> r = report("so3_sampling", samples=200, seed=3)
    >>> r["meta"]["samples"], r["meta"]["seed"]
    (200, 3)
    """
    return _json.loads(_posecov.report_json(fspath(source), **overrides))


_DEFECT = _re.compile(r": topic (?P<topic>.+?), message \d+ \(stamp [^)]*\): (?P<issue>[a-z_0-9]+) — ")


def check(
    source: Union[str, PathLike], allow: Iterable[str] = (), **overrides: Any
) -> Dict[str, Any]:
    """What ``posecov check SOURCE`` finds: the verdict and the defects.

    Returns a dict: ``line`` (the line the CLI prints on stdout), ``exit_code`` (0 ok, 1
    defects found, as the CLI exits), ``ok`` (``exit_code == 0``) and ``defects``: one dict
    per line the CLI prints on stderr (the first defect of each topic; every class found, with
    its counts, is in ``report(source)["topics"][i]["health"]``), ``{"text": ..., "topic": ..., "issue": ...}`` with the
    topic and the defect class (``non_finite``, ``not_psd``, ... as ``--allow`` names them;
    ``None`` for a log-wide defect such as a log cut short). ``allow`` accepts defect classes
    on purpose, as ``--allow``. A scenario or graph with an error raises ``PosecovError``.

    >>> check("camera_on_robot")["ok"]
    True
    >>> [(d["topic"], d["issue"]) for d in check("covariance_health")["defects"]]
    [('/amcl_pose', 'all_zero')]
    """
    line, defects, code = _posecov.check_raw(fspath(source), list(allow), **overrides)
    parsed = []
    for text in defects:
        m = _DEFECT.search(text)
        parsed.append(
            {
                "text": text,
                "topic": m.group("topic") if m else None,
                "issue": m.group("issue") if m else None,
            }
        )
    return {"line": line, "exit_code": code, "ok": code == 0, "defects": parsed}


def figure(source: Union[str, PathLike], path: Union[str, PathLike], **options: Any) -> None:
    """Writes the figure ``posecov figure SOURCE -o PATH`` writes: SVG, PNG or PDF by the
    extension of ``path``.

    Options: ``size`` ((width, height), default (1280, 800)), ``plane`` ("xy", "xz", "yz"),
    ``step`` ("all" or a step number), and the overrides of ``report`` (``samples``,
    ``seed``, ...).

    >>> import tempfile, os
    >>> out = os.path.join(tempfile.mkdtemp(), "camera.svg")
    >>> figure("camera_on_robot", out, samples=200)
    >>> open(out).read().startswith("<svg")
    True
    """
    _posecov.figure_file(fspath(source), fspath(path), **options)


def figure_svg(source: Union[str, PathLike], **options: Any) -> str:
    """The SVG text of ``figure`` (the same options), for a notebook or a web page.

    >>> figure_svg("so3_sampling", samples=100).startswith("<svg")
    True
    """
    return _posecov.figure_svg(fspath(source), **options)


class Figure:
    """A figure that IPython and Jupyter show inline (as SVG): ``Figure("camera_on_robot")``
    as the last expression of a cell, or ``display(Figure(...))``. Options as ``figure``.

    >>> Figure("so3_sampling", samples=100)._repr_svg_().startswith("<svg")
    True
    """

    def __init__(self, source: Union[str, PathLike], **options: Any) -> None:
        self.source = fspath(source)
        self.options = options
        self._svg: Optional[str] = None

    @property
    def svg(self) -> str:
        """The SVG text (drawn once)."""
        if self._svg is None:
            self._svg = figure_svg(self.source, **self.options)
        return self._svg

    def _repr_svg_(self) -> str:
        return self.svg

    def save(self, path: Union[str, PathLike]) -> None:
        """Writes the figure to ``path`` (SVG, PNG or PDF by its extension)."""
        figure(self.source, path, **self.options)

    def __repr__(self) -> str:
        return f"Figure({self.source!r})"


def examples() -> List[tuple]:
    """The bundled examples as (name, format) pairs, in ``posecov list`` order.

    >>> ("camera_on_robot", "TOML scenario") in examples()
    True
    """
    return [tuple(e) for e in _posecov.examples()]


def expand(*args: Union[str, PathLike]) -> List[str]:
    """The inputs ``posecov report ARGS...`` runs: each argument as given, a directory
    replaced by every robot log in it, sorted by name (the CLI's expansion).

    >>> expand("camera_on_robot")
    ['camera_on_robot']
    """
    return list(_posecov.expand([fspath(a) for a in args]))
