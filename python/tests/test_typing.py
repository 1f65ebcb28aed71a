"""The package is typed: mypy --strict passes on it, and the native module's stubs match what
the module has at run time (mypy's stubtest)."""

from __future__ import annotations

import subprocess
import sys

from conftest import REPOSITORY

CACHE = str(REPOSITORY / "target" / "mypy-cache")


def mypy(*arguments: str, cwd) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", *arguments], capture_output=True, text=True, cwd=cwd)


def test_the_package_passes_mypy_strict(tmp_path):
    # From a directory of its own: the installed package, not the sources beside the tests.
    done = mypy("mypy", "--strict", "--cache-dir", CACHE, "-p", "penumbra", cwd=tmp_path)
    assert done.returncode == 0, done.stdout + done.stderr


def test_the_stubs_match_the_native_module(tmp_path):
    done = mypy("mypy.stubtest", "--mypy-config-file", "/dev/null", "penumbra._native", cwd=tmp_path)
    assert done.returncode == 0, done.stdout + done.stderr
