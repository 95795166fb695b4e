# posecov in Jupyter: a recording in the Rerun viewer inline, and a static SVG figure.
#
# A percent-format script: each `# %%` is one notebook cell (Jupyter, VS Code and jupytext
# open it as a notebook). See docs/notebooks.md for the recipe in words.
#
# Run as a plain script (no Jupyter server; this is what CI does), it makes the same widget,
# checks what it holds (the viewer's assets inline, the recording queued for it, the figure)
# and writes one self-contained HTML page that shows both offline:
#
#   POSECOV=target/debug/posecov python docs/notebooks/posecov_notebook.py OUT_DIR
#
# It exits non-zero, saying why, when anything is missing or wrong.

# %%
import base64
import json
import os
import pathlib
import subprocess
import sys

# Offline asset mode: the viewer's JavaScript and WebAssembly travel inside the notebook,
# nothing is fetched from the internet. Must be set before rerun_notebook is imported.
os.environ.setdefault("RERUN_NOTEBOOK_ASSET", "inline")

POSECOV = os.environ.get("POSECOV", "posecov")
SCENARIO = os.environ.get("POSECOV_SCENARIO", "camera_on_robot")
OUT = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 and not sys.argv[1].startswith("-") else "posecov-notebook")
OUT.mkdir(parents=True, exist_ok=True)
rrd_path = OUT / f"{SCENARIO}.rrd"
svg_path = OUT / f"{SCENARIO}.svg"

# The recording (what the viewer shows) and a static figure, both made by posecov itself.
subprocess.run([POSECOV, SCENARIO, "--save", str(rrd_path)], check=True)
subprocess.run([POSECOV, "figure", SCENARIO, "-o", str(svg_path)], check=True)

# %%
import rerun_notebook  # noqa: E402  (after RERUN_NOTEBOOK_ASSET)
from IPython.display import SVG, display  # noqa: E402

viewer = rerun_notebook.Viewer(width="auto", height=520)
viewer.send_rrd(rrd_path.read_bytes())
display(viewer)  # in Jupyter: the Rerun viewer, inline, with the recording

# %%
figure = SVG(filename=str(svg_path))
display(figure)  # in Jupyter: the figure, inline; in a report: the .svg file itself


# %% [markdown]
# Outside Jupyter only: check what the cells made, and write one HTML page with both.
# %%
def fail(why: str) -> None:
    print(f"posecov_notebook: {why}", file=sys.stderr)
    sys.exit(1)


def in_jupyter() -> bool:
    try:
        from IPython import get_ipython
    except ImportError:
        return False
    return get_ipython() is not None


def check() -> tuple[bytes, str]:
    """The recording and the figure, after checking that the widget holds them offline."""
    if rerun_notebook.__version__ != "0.36.3":
        fail(f"rerun-notebook {rerun_notebook.__version__}: posecov writes Rerun 0.36.3 recordings")
    esm = viewer._esm
    if rerun_notebook.ASSET_ENV != "inline" or not isinstance(esm, str):
        fail(f"the viewer's assets are not inline (RERUN_NOTEBOOK_ASSET={rerun_notebook.ASSET_ENV})")
    if "data:application/octet-stream;gzip;base64," not in esm:
        fail("the inline widget does not carry the viewer's WebAssembly")
    rrd = rrd_path.read_bytes()
    if not rrd.startswith(b"RRF2"):
        fail(f"{rrd_path} is not a Rerun recording (it starts with {rrd[:4]!r})")
    queued = [(event, buffers) for event, buffers in viewer._event_queue if event.get("type") == "rrd"]
    if len(queued) != 1 or queued[0][1] is None or bytes(queued[0][1][0]) != rrd:
        fail("the recording was not handed to the viewer widget")
    svg = figure.data or ""
    if "<svg" not in svg or "<text" not in svg:
        fail(f"{svg_path} is not a posecov figure (an SVG with its title and legend)")
    return rrd, svg


def write_page(rrd: bytes, svg: str) -> pathlib.Path:
    """One HTML page, no network: the notebook widget's own module (assets inline) run by a
    minimal host that plays Jupyter's part (the widget's state, its "ready" message, the
    recording as a custom message), then the SVG figure."""
    state = {
        "_width": "auto",
        "_height": 520,
        "_url": None,
        "_panel_states": {"top": "hidden", "blueprint": "collapsed", "selection": "collapsed"},
        "_fallback_token": None,
        "_theme": "dark",
    }
    page = OUT / f"{SCENARIO}.html"
    css = rerun_notebook.CSS_PATH.read_text()
    host = f"""
const esm = {json.dumps(viewer._esm)};
const recording = Uint8Array.from(atob("{base64.b64encode(rrd).decode()}"), (c) => c.charCodeAt(0));
const state = {json.dumps(state)};
const handlers = {{}};
const model = {{
  get: (key) => state[key],
  on: (event, handler) => {{ handlers[event] = handler; }},
  send: (message) => {{
    if (message === "ready") handlers["msg:custom"]({{ type: "rrd" }}, [new DataView(recording.buffer)]);
  }},
}};
const widget = await import(URL.createObjectURL(new Blob([esm], {{ type: "text/javascript" }})));
widget.default.render({{ model, el: document.getElementById("viewer") }});
"""
    page.write_text(
        "<!doctype html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">"
        f"<title>posecov {SCENARIO}</title><style>{css}\nbody{{font-family:sans-serif;margin:12px}}"
        "#viewer{height:520px}figure{margin:12px 0}figure svg{max-width:100%;height:auto}</style></head><body>\n"
        f"<h1>posecov {SCENARIO}</h1>\n<div id=\"viewer\"></div>\n"
        f"<figure>{svg[svg.find('<svg'):]}</figure>\n"
        f"<script type=\"module\">{host}</script>\n</body></html>\n"
    )
    return page


if not in_jupyter():
    recording, drawing = check()
    html = write_page(recording, drawing)
    print(
        f"posecov_notebook: {rrd_path} ({len(recording)} bytes) queued for the inline viewer "
        f"(assets inline, rerun-notebook {rerun_notebook.__version__}); {svg_path} "
        f"({len(drawing)} characters); {html} ({html.stat().st_size} bytes, no network needed)"
    )
