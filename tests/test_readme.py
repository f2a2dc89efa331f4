"""Every example in the README runs: each Python block, and the command lines of the shell
blocks in order, as a new user would type them (the set-up commands aside: CI runs them;
`ecofmaps explore` serves until stopped: tests/web test it in a browser)."""

import os
import re
import shlex
import subprocess
import sys
from pathlib import Path

import pytest

README = Path(__file__).parents[1] / "README.md"
TEXT = README.read_text(encoding="utf-8")
BLOCKS = re.findall(r"```python\n(.*?)```", TEXT, re.DOTALL)
SHELL = re.findall(r"```bash\n(.*?)```", TEXT, re.DOTALL)

#: Lines of the shell blocks not run here: the set-up (CI runs it) and the server.
NOT_RUN = ("python3 -m venv", "pip install", "ecofmaps explore")


def _command_lines() -> list[str]:
    """The shell blocks' commands, continued lines joined, comments and set-up left out."""
    lines = []
    for block in SHELL:
        for line in block.replace("\\\n", " ").splitlines():
            line = line.strip()
            if line and not line.startswith("#") and not any(skip in line for skip in NOT_RUN):
                lines.append(line)
    return lines


def test_readme_has_examples():
    assert BLOCKS and _command_lines()


@pytest.mark.parametrize("block", BLOCKS, ids=[f"block{i}" for i in range(len(BLOCKS))])
def test_readme_example_runs(block, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    exec(compile(block, str(README), "exec"), {"__name__": "readme"})


def test_readme_commands_run_in_order(tmp_path):
    """Each command line in turn, in one folder, with this environment's ecofmaps and
    python first on the PATH: every file a line names is made by an earlier one."""
    bin_dir = str(Path(sys.executable).parent)
    environment = dict(os.environ, PATH=bin_dir + os.pathsep + os.environ.get("PATH", ""))
    for line in _command_lines():
        done = subprocess.run(
            ["bash", "-c", line.replace("python ", f"{shlex.quote(sys.executable)} ", 1)],
            cwd=tmp_path,
            env=environment,
            capture_output=True,
            text=True,
            timeout=300,
        )
        assert done.returncode == 0, f"{line}\n{done.stdout}\n{done.stderr}"
        assert "Traceback" not in done.stderr, line
