"""The examples in python/examples run from a fresh directory and draw their figures."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

from conftest import REPOSITORY

EXAMPLES = sorted((REPOSITORY / "python" / "examples").glob("*.py"))


def test_there_are_examples():
    assert len(EXAMPLES) >= 3


@pytest.mark.parametrize("script", EXAMPLES, ids=lambda p: p.stem)
def test_example_runs_and_draws(script, tmp_path):
    environment = dict(os.environ, MPLBACKEND="Agg")
    done = subprocess.run(
        [sys.executable, str(script), "--out", str(tmp_path)],
        capture_output=True, text=True, cwd=tmp_path, env=environment, timeout=300,
    )
    assert done.returncode == 0, done.stderr
    figures = list(tmp_path.glob("*.png"))
    assert len(figures) == 1, figures
    data = figures[0].read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n" and len(data) > 10_000, (figures[0], len(data))
