"""The wheel installs in a fresh virtual environment and runs the README's one-liner there."""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

from conftest import REPOSITORY


def the_wheel() -> Path:
    """$PENUMBRA_WHEEL (the README's test command sets it), or the newest in target/wheels."""
    if "PENUMBRA_WHEEL" in os.environ:
        return Path(os.environ["PENUMBRA_WHEEL"])
    wheels = sorted((REPOSITORY / "target" / "wheels").glob("penumbra-*.whl"), key=lambda p: p.stat().st_mtime)
    assert wheels, "no wheel in target/wheels: build one with maturin build --release"
    return wheels[-1]


def test_the_wheel_installs_and_runs_in_a_fresh_venv(tmp_path):
    wheel = the_wheel()
    assert re.search(r"-cp310-abi3-", wheel.name), f"{wheel.name} is not one abi3 wheel for CPython 3.10+"
    venv = tmp_path / "venv"
    subprocess.run([sys.executable, "-m", "venv", str(venv)], check=True)
    python = venv / "bin" / "python"
    install = subprocess.run(
        [str(python), "-m", "pip", "install", "--quiet", "--disable-pip-version-check", str(wheel)],
        capture_output=True, text=True,
    )
    assert install.returncode == 0, install.stderr
    one_liner = (
        "import penumbra; s = penumbra.run(penumbra.Scene.builtin('cornell')); print(s.radiosity.shape)"
    )
    done = subprocess.run([str(python), "-c", one_liner], capture_output=True, text=True, cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    assert re.fullmatch(r"\(\d+, 3\)\n", done.stdout), done.stdout
    # Typed: the stubs and the marker are installed.
    site = subprocess.run(
        [str(python), "-c", "import penumbra, os; print(os.path.dirname(penumbra.__file__))"],
        capture_output=True, text=True, check=True,
    ).stdout.strip()
    assert {"py.typed", "_native.pyi"} <= set(os.listdir(site))


def test_the_wheel_installs_on_any_linux_from_2014_on():
    """Tagged manylinux2014 (glibc 2.17), and auditwheel finds nothing in it that needs more."""
    wheel = the_wheel()
    assert re.search(r"manylinux_2_17_x86_64|manylinux2014_x86_64", wheel.name), wheel.name
    show = subprocess.run(
        [sys.executable, "-m", "auditwheel", "show", str(wheel)], capture_output=True, text=True
    )
    assert show.returncode == 0, show.stderr
    text = " ".join(show.stdout.split())
    assert 'consistent with the following platform tag: "manylinux_2_17_x86_64"' in text, show.stdout
