"""posecov in a Jupyter notebook: the figure inline and the Rerun viewer with a recording
(the notebook recipe of docs/guide/python.md; docs/notebooks.md is the same without the package).

The figure needs nothing but the package: ``posecov.Figure(source, **options)`` (SVG, shown
inline by IPython). The interactive 3-D view plays a recording the CLI wrote
(``posecov NAME --save NAME.rrd``; the wheel does not contain Rerun) in the ``rerun-notebook``
widget of Rerun 0.36.3, the version posecov writes: ``pip install rerun-notebook==0.36.3``.

>>> from posecov import notebook
>>> callable(notebook.viewer) and callable(notebook.figure)
True
"""

from __future__ import annotations

import os
from os import PathLike
from typing import Any, Union

from . import Figure

__all__ = ["figure", "viewer"]


def figure(source: Union[str, PathLike], **options: Any) -> Figure:
    """The figure of ``source`` for ``display`` (the same options as ``posecov.figure``).

    >>> figure("so3_sampling", samples=100)._repr_svg_().startswith("<svg")
    True
    """
    return Figure(source, **options)


def viewer(rrd: Union[str, PathLike, bytes], width: Union[int, str] = "auto", height: int = 520,
           offline: bool = True) -> Any:
    """A ``rerun_notebook.Viewer`` playing a recording (a ``.rrd`` path or its bytes), ready for
    ``display``. ``offline``: the viewer's assets travel inside the notebook
    (``RERUN_NOTEBOOK_ASSET=inline``, set before ``rerun_notebook`` is first imported; about
    50 MB per viewer cell) instead of being fetched from the network.

    Needs ``rerun-notebook==0.36.3`` (ImportError otherwise, saying so). In a notebook cell,
    after ``posecov camera_on_robot --save camera.rrd``:

    >>> notebook.viewer("camera.rrd")  # doctest: +SKIP
    """
    if offline:
        os.environ.setdefault("RERUN_NOTEBOOK_ASSET", "inline")
    try:
        import rerun_notebook
    except ImportError as e:  # pragma: no cover - depends on the notebook's environment
        raise ImportError("posecov.notebook.viewer needs the Rerun widget: pip install rerun-notebook==0.36.3") from e
    data = rrd if isinstance(rrd, bytes) else open(os.fspath(rrd), "rb").read()
    widget = rerun_notebook.Viewer(width=width, height=height)
    widget.send_rrd(data)
    return widget
