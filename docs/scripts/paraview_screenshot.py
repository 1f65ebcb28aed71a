"""Screenshot of a penumbra solution.vtp opened in ParaView.

    pvpython docs/scripts/paraview_screenshot.py OUT/solution.vtp docs/paraview.png

Two views side by side, 1280x800: on the left the radiosity as render.png shows
it, on the right its luminance with a colour bar; both with the discontinuity
lines drawn on top, coloured by the boundary they belong to. The camera is the
run's own (render.camera in the report.json beside the VTP) when there is one.
Headless: prefix the command with `xvfb-run -a`.
"""
import json
import math
import os
import sys

from paraview.simple import *

vtp, png = sys.argv[1], sys.argv[2]
report_path = os.path.join(os.path.dirname(os.path.abspath(vtp)), "report.json")
render = json.load(open(report_path))["render"] if os.path.exists(report_path) else {}
# render.png shows (radiosity + ambient) x exposure through the sRGB curve; without
# a report, exposure 1 and no ambient.
exposure = render.get("exposure", 1.0)
ambient = render.get("ambient", [0.0, 0.0, 0.0])

LoadPalette("WhiteBackground")  # white background, black text
W, H = 640, 800  # each of the two views

solution = XMLPolyDataReader(FileName=[vtp])
# The triangles' display colour, in [0, 1] per channel, as render.png computes it.
display_rgb = PythonCalculator(
    Input=solution,
    ArrayName="display",
    Expression="(lambda x: np.where(x <= 0.0031308, 12.92 * x, 1.055 * x ** (1 / 2.4) - 0.055))"
    "(np.clip((radiosity + np.array(%r)) * %r, 0, 1))" % (list(ambient), exposure),
)
# Triangles carry order -1; the segments of the discontinuity lines 0, 1 or 2.
lines = Threshold(Input=solution, Scalars=["CELLS", "order"], ThresholdMethod="Between")
# Set after Scalars: choosing the array resets the range to all of it, -1 included.
lines.LowerThreshold, lines.UpperThreshold = 0, 2


def make_view(title):
    view = CreateView("RenderView")
    view.ViewSize = [W, H]
    view.OrientationAxesVisibility = 0
    camera = render.get("camera")
    if camera:
        view.CameraPosition = camera["eye"]
        view.CameraFocalPoint = camera["target"]
        view.CameraViewUp = camera["up"]
        # fov_deg is vertical over render.png's aspect; widen it so that the
        # published picture's full width fits this narrower view.
        tan_v = math.tan(math.radians(camera["fov_deg"]) / 2)
        tan_h = tan_v * render["width"] / render["height"]
        view.CameraViewAngle = math.degrees(2 * math.atan(max(tan_v, tan_h * H / W)))
    else:
        view.ResetCamera()
    label = Show(Text(Text=title), view)
    label.WindowLocation = "Upper Center"
    label.FontSize = 20
    return view


def show_surfaces(source, view):
    shown = Show(source, view)
    # The colours are the solution's light, not something to shade again with
    # ParaView's headlight.
    shown.Ambient, shown.Diffuse = 1.0, 0.0
    return shown


def show_lines(view):
    shown = Show(lines, view)
    ColorBy(shown, ("CELLS", "boundary"))
    # Plain lines: ParaView 5.11 draws tubes ("Render Lines As Tubes") at the depth
    # of the surface they lie on, where they z-fight and mostly vanish.
    shown.LineWidth = 3
    shown.Ambient, shown.Diffuse = 1.0, 0.0
    codes = GetColorTransferFunction("boundary")
    codes.InterpretValuesAsCategories = 1
    codes.Annotations = ["0", "umbra", "1", "penumbra", "2", "inner"]
    codes.IndexedColors = [0.0, 0.35, 1.0, 1.0, 0.0, 0.85, 1.0, 0.75, 0.0]
    return shown


def bottom_bar(lut, view, title):
    bar = GetScalarBar(lut, view)
    bar.Title, bar.ComponentTitle = title, ""
    bar.Orientation = "Horizontal"
    bar.WindowLocation = "Lower Center"
    bar.ScalarBarLength = 0.8
    bar.TitleFontSize = bar.LabelFontSize = 16
    bar.RangeLabelFormat = "%.2f"
    bar.Visibility = 1


# Left: the radiosity in its own colours (MapScalars off: the array is the colour).
left = make_view("radiosity (as render.png shows it)")
colours = show_surfaces(display_rgb, left)
ColorBy(colours, ("POINTS", "display"))
colours.MapScalars = 0
show_lines(left)
bottom_bar(GetColorTransferFunction("boundary"), left, "discontinuity lines")

# Right: luminance, from black to the value render.png shows as white (the
# light, far brighter, clamps to white as it does there).
right = make_view("luminance")
grey = show_surfaces(solution, right)
ColorBy(grey, ("POINTS", "luminance"))
lum = GetColorTransferFunction("luminance")
lum.ApplyPreset("Grayscale", True)
lum.AutomaticRescaleRangeMode = "Never"
lum.RescaleTransferFunction(0.0, 1.0 / exposure)
show_lines(right)
bottom_bar(lum, right, "luminance of radiosity, W/m\u00b2")

layout = CreateLayout("penumbra")
layout.SplitHorizontal(0, 0.5)
AssignViewToLayout(view=left, layout=layout, hint=1)
AssignViewToLayout(view=right, layout=layout, hint=2)
SaveScreenshot(png, layout, ImageResolution=[2 * W, H], SeparatorWidth=2)
