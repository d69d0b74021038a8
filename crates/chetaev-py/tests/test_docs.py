"""The Python guide (docs/python.md) and the README's Python example run as written."""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[3]


def python_blocks(path: Path) -> list[str]:
    """The ```python blocks of a markdown file, in order."""
    return re.findall(r"```python\n(.*?)```", path.read_text(encoding="utf-8"), flags=re.S)


def run_as_script(code: str, folder: Path) -> subprocess.CompletedProcess[str]:
    script = folder / "guide.py"
    script.write_text(code, encoding="utf-8")
    env = dict(os.environ, MPLBACKEND="Agg")
    return subprocess.run(
        [sys.executable, str(script)],
        cwd=folder,
        env=env,
        capture_output=True,
        text=True,
        timeout=600,
    )


def test_the_python_guide_runs_as_one_script_with_its_checks(tmp_path: Path) -> None:
    blocks = python_blocks(ROOT / "docs" / "python.md")
    assert len(blocks) >= 8, "the guide's code blocks were not found"
    done = run_as_script("\n".join(blocks), tmp_path)
    assert done.returncode == 0, done.stderr[-4000:]
    # The pictures the guide shows are the ones it makes.
    for picture in ["python-rolling-disc.png", "python-sweep.png"]:
        assert (tmp_path / picture).stat().st_size > 10_000


def test_the_guides_printed_outputs_are_what_the_code_prints(tmp_path: Path) -> None:
    text = (ROOT / "docs" / "python.md").read_text(encoding="utf-8")
    blocks = python_blocks(ROOT / "docs" / "python.md")
    # The first block prints T and R; the guide shows them below it.
    done = run_as_script(blocks[0], tmp_path)
    assert done.returncode == 0, done.stderr[-4000:]
    first_line = done.stdout.strip().splitlines()[0]
    t_value, r_value = (float(v) for v in first_line.split())
    shown = re.search(r"```text\n([0-9.e+-]+) ([0-9.e+-]+)\n```", text)
    assert shown is not None
    # Printed to full precision: equal to rounding of the last digits (1e-13 relative).
    assert t_value == pytest.approx(float(shown.group(1)), rel=1e-13)
    assert r_value == pytest.approx(float(shown.group(2)), rel=1e-13)


def test_the_readmes_python_example_runs(tmp_path: Path) -> None:
    blocks = python_blocks(ROOT / "README.md")
    assert blocks, "the README has no Python example"
    done = run_as_script(blocks[0], tmp_path)
    assert done.returncode == 0, done.stderr[-4000:]
    assert done.stdout.startswith("1.08503850194")
