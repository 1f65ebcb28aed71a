"""How penumbra's browser tests and screenshots start Chromium: Debian's `chromium`, driven by
Playwright, which downloads no browser here."""

import os
import shutil

# WebGL in headless Chromium needs a software renderer: SwiftShader through ANGLE. Recent
# Chromium no longer falls back to it on its own, hence --enable-unsafe-swiftshader; without
# --use-angle=swiftshader it logs a "GPU stall due to ReadPixels" warning per frame read. Root
# cannot use the sandbox. The rest keeps the browser off the network.
CHROMIUM_ARGS = [
    "--no-sandbox",
    "--use-angle=swiftshader",
    "--enable-unsafe-swiftshader",
    "--disable-background-networking",
    "--disable-component-update",
    "--no-first-run",
    "--disable-sync",
]


def chromium_path() -> str:
    """$PENUMBRA_CHROMIUM, else the `chromium` on the PATH, else Debian's place for it."""
    return os.environ.get("PENUMBRA_CHROMIUM") or shutil.which("chromium") or "/usr/bin/chromium"
