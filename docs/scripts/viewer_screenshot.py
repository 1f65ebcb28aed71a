"""A screenshot of a run's viewer page (index.html), as docs/viewer.png shows it.

    penumbra run cornell --out /tmp/cornell --quiet
    python docs/scripts/viewer_screenshot.py /tmp/cornell/index.html docs/viewer.png --click 453,0,113

Opens the page from disk in Debian's Chromium (headless, software WebGL), driven by Playwright
(pip install playwright; it downloads no browser), waits until the page has drawn, clicks the
scene point given (if any) to show what the page reads there, and saves a 1280x800 screenshot.
"""

import argparse
import sys
from pathlib import Path

from playwright.sync_api import sync_playwright

# The arguments the browser tests start Chromium with.
sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "tests" / "tools"))
from browser import CHROMIUM_ARGS, chromium_path  # noqa: E402

def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("page", type=Path, help="the index.html of a run")
    parser.add_argument("png", type=Path, help="where to save the screenshot")
    parser.add_argument("--click", help="a scene point X,Y,Z to click, in the scene's units")
    args = parser.parse_args()
    chromium = chromium_path()
    with sync_playwright() as playwright:
        browser = playwright.chromium.launch(executable_path=chromium, args=CHROMIUM_ARGS)
        page = browser.new_page(viewport={"width": 1280, "height": 800})
        page.goto(args.page.resolve().as_uri())
        page.wait_for_function("window.penumbraReady === true || window.penumbraError !== undefined", timeout=120_000)
        error = page.evaluate("window.penumbraError")
        if error:
            print(f"the page reports: {error}", file=sys.stderr)
            return 1
        if args.click:
            point = [float(c) for c in args.click.split(",")]
            at = page.evaluate("(p) => window.penumbraViewer.project(p)", point)
            page.mouse.click(at["x"], at["y"])
        # Two frames after the last input, so the picture holds its effect.
        page.evaluate("() => new Promise(r => requestAnimationFrame(() => requestAnimationFrame(r)))")
        page.screenshot(path=str(args.png))
        browser.close()
    return 0


if __name__ == "__main__":
    sys.exit(main())
