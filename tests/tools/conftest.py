"""Fixtures for the tests of what penumbra writes for other tools: the CLI binary, a headless
Chromium driven by Playwright, and a directory for the pictures the tests leave behind."""

import os
from pathlib import Path

import pytest

from browser import CHROMIUM_ARGS, chromium_path

ROOT = Path(__file__).resolve().parents[2]

def _missing(reason: str):
    """Skips the test, or fails it when PENUMBRA_REQUIRE_BROWSER is set (as in CI)."""
    if os.environ.get("PENUMBRA_REQUIRE_BROWSER"):
        pytest.fail(reason)
    pytest.skip(reason)


@pytest.fixture(scope="session")
def penumbra_cli() -> Path:
    """The penumbra binary: $PENUMBRA_CLI, else target/release/penumbra."""
    cli = Path(os.environ.get("PENUMBRA_CLI", ROOT / "target" / "release" / "penumbra"))
    if not cli.is_file():
        pytest.fail(f"no penumbra binary at {cli}: run `cargo build --release` or set PENUMBRA_CLI")
    return cli


@pytest.fixture(scope="session")
def browser():
    """A headless Chromium (the system's, or $PENUMBRA_CHROMIUM)."""
    try:
        from playwright.sync_api import sync_playwright
    except ImportError:
        _missing("the browser tests need Playwright: pip install playwright")
    executable = chromium_path()
    if not Path(executable).is_file():
        _missing(f"the browser tests need Chromium (apt-get install chromium); none at {executable}")
    with sync_playwright() as playwright:
        browser = playwright.chromium.launch(executable_path=executable, args=CHROMIUM_ARGS)
        yield browser
        browser.close()


@pytest.fixture
def test_output(tmp_path) -> Path:
    """Where a test leaves files worth looking at: $PENUMBRA_TEST_OUTPUT, else its tmp_path."""
    out = os.environ.get("PENUMBRA_TEST_OUTPUT")
    if not out:
        return tmp_path
    path = Path(out)
    path.mkdir(parents=True, exist_ok=True)
    return path
