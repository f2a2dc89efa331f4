"""Every example in the README runs: each Python block, and the shell blocks as written, in
order, as a new user types them into one shell in a fresh copy of the repository (the test
suite's own command aside; `ecofmaps explore` serves until stopped: tests/web test it)."""

import os
import re
import shutil
import subprocess
import sys
import sysconfig
from pathlib import Path

import pytest

ROOT = Path(__file__).parents[1]
README = ROOT / "README.md"
TEXT = README.read_text(encoding="utf-8")
BLOCKS = re.findall(r"```python\n(.*?)```", TEXT, re.DOTALL)
SHELL = re.findall(r"```bash\n(.*?)```", TEXT, re.DOTALL)

#: What a copy of the repository leaves out: what set-up, builds and runs make.
NOT_COPIED = (
    ".git",
    ".venv",
    "build",
    "site",
    "*.egg-info",
    "__pycache__",
    ".*_cache",
    ".hypothesis",
)


def _shell_script() -> str:
    """The shell blocks as one script, each announced on stderr: all but the one that runs the
    test suite, and without the line that starts the explorer's server."""
    script = ["set -eo pipefail"]
    for number, block in enumerate(SHELL):
        if "pytest" in block:
            continue
        lines = [line for line in block.splitlines() if not line.startswith("ecofmaps explore")]
        script += [f"echo '--- README shell block {number}' >&2", *lines]
    return "\n".join(script) + "\n"


def test_readme_has_examples():
    assert BLOCKS and SHELL
    assert "ecofmaps explore" in TEXT and ". .venv/bin/activate" in _shell_script()


@pytest.mark.parametrize("block", BLOCKS, ids=[f"block{i}" for i in range(len(BLOCKS))])
def test_readme_example_runs(block, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    exec(compile(block, str(README), "exec"), {"__name__": "readme"})


@pytest.mark.slow
def test_readme_shell_blocks_run_as_written(tmp_path):
    """In a copy of the repository, one shell runs every shell block in turn: the set-up
    creates `.venv` and installs ecofmaps from the copy, the blocks after it run in that
    environment once activated, and every file a line names is made by an earlier one.

    The fresh `.venv` sees this environment's installed packages (a .pth file, made before
    the set-up runs), so pip installs ecofmaps alone: it downloads nothing but the setuptools
    that builds it."""
    copy = tmp_path / "ecofmaps"
    shutil.copytree(ROOT, copy, ignore=shutil.ignore_patterns(*NOT_COPIED))
    subprocess.run([sys.executable, "-m", "venv", copy / ".venv"], check=True, timeout=300)
    (site,) = (copy / ".venv" / "lib").glob("python*/site-packages")
    (site / "test-environment.pth").write_text(sysconfig.get_paths()["purelib"] + "\n")
    # A new user's shell: no environment activated, this one's Python not on the PATH.
    environment = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "VIRTUAL_ENV")}
    here = str(Path(sys.executable).parent)
    path = [folder for folder in environment.get("PATH", "").split(os.pathsep) if folder != here]
    environment["PATH"] = os.pathsep.join(path)
    environment.update(PIP_NO_INPUT="1", PIP_DISABLE_PIP_VERSION_CHECK="1")
    # Then: which ecofmaps the shell runs, and which one Python imports outside the copy.
    script = (
        _shell_script()
        + 'command -v ecofmaps\ncd / && python -c "import ecofmaps as e; print(e.__file__)"\n'
    )
    done = subprocess.run(
        ["bash", "-c", script],
        cwd=copy,
        env=environment,
        capture_output=True,
        text=True,
        timeout=1800,
    )
    assert done.returncode == 0, f"{done.stdout[-3000:]}\n{done.stderr[-5000:]}"
    assert "Traceback" not in done.stderr, done.stderr[-5000:]
    # The blocks after the set-up ran the ecofmaps installed in the fresh .venv.
    *_, command, imported = done.stdout.strip().splitlines()
    assert Path(command) == copy / ".venv" / "bin" / "ecofmaps", command
    assert Path(imported).is_relative_to(copy / ".venv"), imported
    for made in ("figures/fig11b.png", "fig11.nc", "corrected.csv", "results.csv", "report.html"):
        assert (copy / made).exists(), made
