"""docs/guide/python.md: every ```python block runs, in order, in one namespace (a fresh
working directory), against the installed wheel; a block right after a
``<!-- not run: ... -->`` comment is skipped (it needs what the CI venv does not have)."""

import contextlib
import io
import os
import re

BLOCK = re.compile(r"(<!-- not run:[^>]*-->\n)?```python\n(.*?)```", re.S)


def test_every_python_block_of_the_page_runs(root, tmp_path):
    page = (root / "docs/guide/python.md").read_text()
    blocks = [(skip, code) for skip, code in BLOCK.findall(page)]
    assert len(blocks) >= 6
    namespace = {"__name__": "guide"}
    cwd = os.getcwd()
    os.chdir(tmp_path)
    try:
        for k, (skip, code) in enumerate(blocks):
            if skip:
                continue
            with contextlib.redirect_stdout(io.StringIO()):
                exec(compile(code, f"docs/guide/python.md block {k + 1}", "exec"), namespace)
    finally:
        os.chdir(cwd)
    assert (tmp_path / "camera.pdf").read_bytes().startswith(b"%PDF")
    assert (tmp_path / "camera.png").read_bytes().startswith(b"\x89PNG")
