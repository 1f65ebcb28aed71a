"""Shared set-up: the command line built beside the package, for comparisons with it."""

from __future__ import annotations

import json
import os
import subprocess
from pathlib import Path

import numpy as np
import pytest

REPOSITORY = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="session")
def cli() -> Path:
    """The `penumbra` binary: $PENUMBRA_CLI, or the release build of this checkout (the README's
    test command builds it first)."""
    path = Path(os.environ.get("PENUMBRA_CLI", REPOSITORY / "target" / "release" / "penumbra"))
    assert path.is_file(), f"no penumbra binary at {path}: run `cargo build --release` first"
    return path


def run_cli(cli: Path, *arguments: str, cwd: Path) -> subprocess.CompletedProcess:
    """Runs the command line quietly and returns what it did, failing the test if it failed."""
    done = subprocess.run([str(cli), *arguments], cwd=cwd, capture_output=True, text=True)
    assert done.returncode == 0, f"penumbra {' '.join(arguments)} failed:\n{done.stderr}"
    return done


def solution_arrays(path: Path) -> dict[str, np.ndarray]:
    """solution.json's arrays, concatenated over surfaces as `Solution` holds them."""
    surfaces = json.loads(path.read_text())["surfaces"]
    offsets = np.cumsum([0] + [len(s["vertices"]) for s in surfaces])
    return {
        "vertices": np.concatenate([np.array(s["vertices"], dtype=float).reshape(-1, 3) for s in surfaces]),
        "radiosity": np.concatenate([np.array(s["radiosity"], dtype=float).reshape(-1, 3) for s in surfaces]),
        "triangles": np.concatenate(
            [np.array(s["triangles"], dtype=np.uint32).reshape(-1, 3) + np.uint32(o) for s, o in zip(surfaces, offsets)]
        ),
        "segments": np.array(
            [[d["from"], d["to"]] for s in surfaces for d in s["discontinuities"]], dtype=float
        ).reshape(-1, 2, 3),
        "event": np.array([d["event"] for s in surfaces for d in s["discontinuities"]], dtype=str),
        "order": np.array([d["order"] for s in surfaces for d in s["discontinuities"]], dtype=np.uint8),
    }
