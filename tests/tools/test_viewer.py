"""The page `penumbra run --export html` writes, opened from disk in a headless Chromium: it
draws the run, its controls change what is drawn, its colours are render.png's, a click reads
the values on a surface, and bad data gives a message instead of a blank page."""

import base64
import json
import math
import re
import subprocess
from pathlib import Path

import numpy as np
import pytest

# Software WebGL is slow: the first frame of a large run can take many seconds to load.
READY_TIMEOUT_MS = 60_000
VIEWPORT = {"width": 1280, "height": 800}
# Small runs keep the test quick; the mesh still follows every discontinuity. Adaptive
# refinement starts from a tenth of the budget, which must hold the discontinuities.
RUN_OPTIONS = ["--max-elements", "3000"]
ADAPTIVE_OPTIONS = ["--max-elements", "6000", "--refine-tol", "0.05"]
BACKGROUND = (0x16, 0x18, 0x1B)


def export(cli: Path, out: Path, *options: str) -> Path:
    subprocess.run(
        [str(cli), "run", "cornell", "--export", "html", "--out", str(out), "--quiet", *options],
        check=True,
    )
    return out


@pytest.fixture(scope="module")
def run_dir(penumbra_cli, tmp_path_factory) -> Path:
    return export(penumbra_cli, tmp_path_factory.mktemp("viewer"), *RUN_OPTIONS)


@pytest.fixture(scope="module")
def direct_dir(penumbra_cli, tmp_path_factory) -> Path:
    """A direct-only run: its render adds the ambient term (the light not shot), each surface its
    reflectance's share."""
    return export(penumbra_cli, tmp_path_factory.mktemp("viewer-direct"), *RUN_OPTIONS, "--direct-only")


@pytest.fixture(scope="module")
def adaptive_dir(penumbra_cli, tmp_path_factory) -> Path:
    return export(penumbra_cli, tmp_path_factory.mktemp("viewer-adaptive"), *ADAPTIVE_OPTIONS)


# Draws an image or canvas onto a 2D canvas and returns its RGBA pixels in base64: far quicker to
# hand to Python than an array of numbers.
READ_PIXELS = """(source, width, height) => {
  const copy = document.createElement('canvas');
  copy.width = width;
  copy.height = height;
  const context = copy.getContext('2d');
  context.drawImage(source, 0, 0);
  const rgba = context.getImageData(0, 0, width, height).data;
  let binary = '';
  for (let i = 0; i < rgba.length; i += 0x8000) {
    binary += String.fromCharCode(...rgba.subarray(i, i + 0x8000));
  }
  return {width, height, rgba: btoa(binary)};
}"""


def decode_pixels(data: dict) -> np.ndarray:
    """(height, width, 3) uint8 from READ_PIXELS's answer."""
    rgba = np.frombuffer(base64.b64decode(data["rgba"]), np.uint8)
    return rgba.reshape(data["height"], data["width"], 4)[:, :, :3]


class Page:
    """A viewer page in the browser, with every console error and uncaught exception it raised."""

    def __init__(self, browser, path: Path):
        self.context = browser.new_context(viewport=VIEWPORT, device_scale_factor=1)
        self.page = self.context.new_page()
        self.problems: list[str] = []
        self.page.on("console", lambda m: m.type == "error" and self.problems.append(f"console: {m.text}"))
        self.page.on("pageerror", lambda e: self.problems.append(f"page error: {e}"))
        # The script runs, and draws the first frame, as the page loads.
        self.page.goto(path.as_uri(), timeout=READY_TIMEOUT_MS)
        started = self.page.evaluate("window.penumbraReady === true || window.penumbraError !== undefined")
        assert started, f"the page's script did not run: {self.page.locator('#message').inner_text()!r}"

    def close(self):
        self.context.close()

    def error(self):
        return self.page.evaluate("window.penumbraError")

    def frame(self) -> int:
        return self.page.evaluate("window.penumbraFrame")

    def after_frame(self, action) -> None:
        """Runs `action`, then waits until the page has drawn a new frame."""
        before = self.frame()
        action()
        self.page.wait_for_function(f"window.penumbraFrame > {before}", timeout=READY_TIMEOUT_MS)

    def pixels(self) -> np.ndarray:
        """The 3D view's pixels, (height, width, 3) uint8."""
        data = self.page.evaluate(
            f"""() => {{
              const canvas = document.querySelector('#view canvas');
              return ({READ_PIXELS})(canvas, canvas.width, canvas.height);
            }}"""
        )
        return decode_pixels(data)

    def canvas_point(self, point) -> tuple[float, float]:
        """Where a scene point is drawn, in the page's CSS pixels."""
        p = self.page.evaluate("(p) => window.penumbraViewer.project(p)", list(map(float, point)))
        return p["x"], p["y"]


@pytest.fixture
def open_page(browser):
    pages = []

    def open_(path: Path) -> Page:
        page = Page(browser, path)
        pages.append(page)
        return page

    yield open_
    for page in pages:
        page.close()


def changed(a: np.ndarray, b: np.ndarray) -> int:
    return int(np.any(a != b, axis=2).sum())


def surfaces(run: Path) -> dict:
    solution = json.loads((run / "solution.json").read_text())
    return {s["name"]: np.array(s["vertices"], float) for s in solution["surfaces"]}


def floor_point(run: Path) -> np.ndarray:
    """A point on the Cornell box's floor, near its open front on the left: in view and in the
    clear of the blocks."""
    floor = surfaces(run)["floor"]
    lo, hi = floor.min(axis=0), floor.max(axis=0)
    return np.array([lo[0] + 0.75 * (hi[0] - lo[0]), floor[:, 1].mean(), lo[2] + 0.15 * (hi[2] - lo[2])])


def test_the_page_draws_the_run_and_its_controls_change_the_view(open_page, run_dir, test_output):
    page = open_page(run_dir / "index.html")
    assert page.error() is None
    assert page.page.evaluate("document.body.dataset.ready") == "true"

    first = page.pixels()
    colours = np.unique(first.reshape(-1, 3), axis=0)
    assert len(colours) > 1000, f"only {len(colours)} colours: the view looks blank"
    background = np.all(first == BACKGROUND, axis=2).mean()
    assert background < 0.5, f"{background:.0%} of the view is background"

    report = json.loads((run_dir / "report.json").read_text())
    discontinuities = report["discontinuities"]
    for order in range(3):
        toggle = page.page.locator(f"#toggle-d{order}")
        if discontinuities[f"order_{order}_segments"] == 0:
            assert toggle.is_disabled()
            continue
        assert toggle.is_checked()
        before = page.pixels()
        page.after_frame(toggle.uncheck)
        assert changed(before, page.pixels()) > 50, f"hiding D{order} lines changed nothing"
        page.after_frame(toggle.check)
        assert changed(before, page.pixels()) == 0

    before = page.pixels()
    page.after_frame(lambda: page.page.check("#toggle-edges"))
    with_edges = page.pixels()
    assert changed(before, with_edges) > 5000, "mesh edges changed too little"
    page.page.screenshot(path=test_output / "viewer-edges.png")
    page.after_frame(lambda: page.page.uncheck("#toggle-edges"))

    modes = page.page.eval_on_selector_all("#colour-mode option", "options => options.map(o => o.value)")
    assert modes == ["radiosity", "direct", "indirect"]
    for mode in ["direct", "indirect"]:
        page.after_frame(lambda: page.page.select_option("#colour-mode", mode))
        assert changed(before, page.pixels()) > 10000, f"colour by {mode} looks like radiosity"
    page.after_frame(lambda: page.page.select_option("#colour-mode", "radiosity"))
    assert changed(before, page.pixels()) == 0

    assert page.page.locator("#pick").is_hidden()
    x, y = page.canvas_point(floor_point(run_dir))
    page.after_frame(lambda: page.page.mouse.click(x, y))
    panel = page.page.locator("#pick")
    assert panel.is_visible()
    assert page.page.locator("#pick-surface").inner_text() == "floor"
    text = panel.inner_text()
    assert "interpolated" in text
    for row in ["radiosity", "direct", "indirect"]:
        assert re.search(rf"{row}\s+[0-9.e-]+\s+[0-9.e-]+\s+[0-9.e-]+\s+[0-9.e-]+", text), text

    legend = page.page.locator("#side").inner_text()
    assert f"{report['counts']['triangles']:,}" in legend
    assert report["method"]["solver"] in legend

    shot = test_output / "viewer.png"
    page.page.screenshot(path=shot)
    print(f"viewer screenshot: {shot}")
    assert page.problems == []


def pinhole_pixel(camera: dict, width: int, height: int, point) -> tuple[int, int]:
    """The pixel of render.png that `point` falls in (viz/src/camera.rs's projection)."""
    eye, target, up = (np.array(camera[k], float) for k in ("eye", "target", "up"))
    forward = (target - eye) / np.linalg.norm(target - eye)
    right = np.cross(forward, up)
    right /= np.linalg.norm(right)
    true_up = np.cross(right, forward)
    d = np.asarray(point, float) - eye
    z = d @ forward
    focal = 0.5 * height / math.tan(math.radians(camera["fov_deg"]) / 2)
    return int(0.5 * width + focal * (d @ right) / z), int(0.5 * height - focal * (d @ true_up) / z)


@pytest.mark.parametrize("run", ["run_dir", "direct_dir"])
def test_radiosity_colours_are_those_of_render_png(open_page, request, run):
    run_dir = request.getfixturevalue(run)
    report = json.loads((run_dir / "report.json").read_text())
    render = report["render"]
    if run == "direct_dir":
        assert min(render["ambient"]) > 0, "a direct-only run shows an ambient term"
    page = open_page(run_dir / "index.html")
    for order in range(3):
        toggle = page.page.locator(f"#toggle-d{order}")
        if toggle.is_checked():
            page.after_frame(toggle.uncheck)
    shown = page.pixels()
    # render.png decoded by the browser (a data: URL leaves the canvas readable).
    png = base64.b64encode((run_dir / "render.png").read_bytes()).decode()
    rendered = decode_pixels(
        page.page.evaluate(
            f"""async (png) => {{
              const image = new Image();
              image.src = 'data:image/png;base64,' + png;
              await image.decode();
              return ({READ_PIXELS})(image, image.width, image.height);
            }}""",
            png,
        )
    )
    assert rendered.shape == (render["height"], render["width"], 3)
    walls = surfaces(run_dir)
    points = [walls[name].mean(axis=0) for name in ("back_wall", "green_wall", "red_wall_high")]
    points.append(floor_point(run_dir))
    canvas = page.page.locator("#view canvas").bounding_box()
    for point in points:
        u, v = pinhole_pixel(render["camera"], render["width"], render["height"], point)
        x, y = page.canvas_point(point)
        here = shown[int(y - canvas["y"]), int(x - canvas["x"])].astype(int)
        there = rendered[v, u].astype(int)
        print(f"at {np.round(point, 1)}: the page shows {here}, render.png {there}")
        assert np.abs(here - there).max() <= 3, f"at {point}: the page shows {here}, render.png {there}"
    assert page.problems == []


def test_an_adaptive_run_can_be_coloured_by_its_error_indicator(open_page, adaptive_dir, test_output):
    page = open_page(adaptive_dir / "index.html")
    assert page.error() is None
    modes = page.page.eval_on_selector_all("#colour-mode option", "options => options.map(o => o.value)")
    assert modes == ["radiosity", "direct", "indirect", "error"]
    before = page.pixels()
    page.after_frame(lambda: page.page.select_option("#colour-mode", "error"))
    assert changed(before, page.pixels()) > 10000
    assert re.search(r"(log|linear) scale", page.page.locator("#side").inner_text())
    page.page.screenshot(path=test_output / "viewer-error.png")
    assert page.problems == []


def test_markup_in_names_does_not_break_the_page(open_page, penumbra_cli, tmp_path):
    """`</script>` would close the data's element; `<!--<script>` would keep it open past its end."""
    dump = subprocess.run(
        [str(penumbra_cli), "scenes", "--dump", "textbook"], check=True, capture_output=True, text=True
    )
    scene = json.loads(dump.stdout)
    scene["surfaces"][-1]["name"] = "floor <!--<script> </script>"
    path = tmp_path / "scene.json"
    path.write_text(json.dumps(scene))
    out = tmp_path / "out"
    subprocess.run(
        [str(penumbra_cli), "run", str(path), "--export", "html", "--out", str(out), "--quiet", *RUN_OPTIONS],
        check=True,
    )
    page = open_page(out / "index.html")
    assert page.error() is None
    assert page.page.evaluate("window.penumbraReady") is True
    assert page.problems == []


def replace_data(page: str, new: str) -> str:
    start = page.index('<script id="penumbra-data" type="application/json">')
    start = page.index(">", start) + 1
    end = page.index("</script>", start)
    return page[:start] + new + page[end:]


def data_block(page: str) -> dict:
    start = page.index('<script id="penumbra-data" type="application/json">')
    start = page.index(">", start) + 1
    return json.loads(page[start : page.index("</script>", start)])


def corrupt_json(page: str) -> str:
    text = json.dumps(data_block(page)).replace("</", "<\\/")
    return replace_data(page, text[: len(text) // 2])


def corrupt_array(page: str) -> str:
    data = data_block(page)
    data["arrays"]["index"] = data["arrays"]["index"][:-8]
    return replace_data(page, json.dumps(data).replace("</", "<\\/"))


def corrupt_format(page: str) -> str:
    data = data_block(page)
    data["format"] = "penumbra-viewer/999"
    return replace_data(page, json.dumps(data).replace("</", "<\\/"))


@pytest.mark.parametrize(
    "corrupt, words",
    [
        (corrupt_json, "not valid JSON"),
        (corrupt_array, "arrays.index"),
        (corrupt_format, "penumbra-viewer/999"),
    ],
    ids=["json", "array-length", "format"],
)
def test_bad_data_gives_a_readable_message(open_page, run_dir, tmp_path, corrupt, words):
    bad = tmp_path / "index.html"
    bad.write_text(corrupt((run_dir / "index.html").read_text()))
    page = open_page(bad)
    error = page.error()
    assert isinstance(error, str) and words in error
    message = page.page.locator("#message")
    assert message.is_visible()
    assert words in message.inner_text()
    assert page.page.evaluate("window.penumbraReady") is None
    assert page.page.evaluate("document.body.dataset.error") == "true"
    assert page.problems == []
