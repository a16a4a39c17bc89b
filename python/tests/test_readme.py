"""The README's Python examples run as written, from the repository root."""

import os
import re

from conftest import REPO


def test_readme_python_blocks_run(capsys):
    text = (REPO / "README.md").read_text()
    blocks = re.findall(r"```python\n(.*?)```", text, re.S)
    assert len(blocks) >= 2
    # `pip install ./python` installs the package the suite already imports.
    namespace = {}
    cwd = os.getcwd()
    os.chdir(REPO)
    try:
        for block in blocks:
            exec(compile(block, "README.md", "exec"), namespace)
    finally:
        os.chdir(cwd)
    assert namespace["w"].shape == (2,)
    assert namespace["W"].shape == (2,)
    assert namespace["report"]["closed"] is True
    assert "True 0" in capsys.readouterr().out
