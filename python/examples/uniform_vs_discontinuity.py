"""Uniform against discontinuity meshes: the error of linear interpolation on the textbook floor.

Runs the built-in textbook scene (a unit square light at height 3, a unit square blocker at
height 1, a 6 x 6 floor at z = 0) with `direct_only=True`, which makes the radiosity at every
vertex exact, on uniform and discontinuity meshes at several element budgets. What is left is
the error of interpolating linearly between the vertices: at 20,000 random points on the floor,
the radiosity interpolated over the floor's triangles against the exact value, emission +
reflectance x `penumbra.direct_light`. Plots and prints the RMS error relative to the mean
exact radiosity against the floor's triangles. About 1.5 s on 2 cores.

    python python/examples/uniform_vs_discontinuity.py --out docs/python-meshes.png
"""

import argparse
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
from matplotlib.ticker import NullFormatter, StrMethodFormatter
from matplotlib.tri import LinearTriInterpolator, Triangulation

import penumbra


def png_path(out: str, name: str) -> Path:
    """``out`` itself, or ``out/name`` when ``out`` is a directory."""
    path = Path(out) / name if Path(out).is_dir() or out.endswith("/") else Path(out)
    path.parent.mkdir(parents=True, exist_ok=True)
    return path


def interpolate(uv: np.ndarray, triangles: np.ndarray, values: np.ndarray, at: np.ndarray):
    """``values`` at a mesh's vertices ``uv`` (2D), linear over its ``triangles``, at the points
    ``at`` (NaN off the mesh). Across contact lines a mesh has two vertices at one position, one
    per side; matplotlib's TriFinder refuses those, so triangles are found with them merged."""
    unique, merged = np.unique(uv, axis=0, return_inverse=True)
    finder = Triangulation(*unique.T, merged.reshape(-1)[triangles]).get_trifinder()
    mesh = Triangulation(*uv.T, triangles)
    return LinearTriInterpolator(mesh, values, trifinder=finder)(*at.T).filled(np.nan)


parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
parser.add_argument("--out", default=".", help="PNG file, or directory for uniform_vs_discontinuity.png")
parser.add_argument("--budgets", type=int, nargs="+", default=[500, 1000, 2000, 4000, 8000],
                    help="max_elements of each run, for the whole scene")
args = parser.parse_args()
path = png_path(args.out, "uniform_vs_discontinuity.png")

scene = penumbra.Scene.builtin("textbook")
f = scene.surface_id("floor")
corners = scene.polygons[f]  # the square [-3, 3]^2 in the plane z = 0, facing +z
assert np.allclose(scene.normals[f], [0, 0, 1]) and not corners[:, 2].any()
xy = np.random.default_rng(1).uniform(corners.min(axis=0)[:2], corners.max(axis=0)[:2], (20_000, 2))
points = np.c_[xy, np.zeros(len(xy))]
exact = (scene.emission[f] + scene.reflectance[f] * penumbra.direct_light(
    scene, points, [0, 0, 1], surfaces=np.full(len(points), f))).mean(axis=1)

results = {"uniform": [], "discontinuity": []}  # (floor triangles, RMS error / mean) per budget
for budget in args.budgets:
    for mesh, rows in results.items():
        floor = penumbra.run(scene, mesh=mesh, max_elements=budget, direct_only=True)["floor"]
        interpolated = interpolate(floor.vertices[:, :2], floor.triangles,
                                   floor.radiosity.mean(axis=1), xy)
        rows.append((len(floor.triangles), np.sqrt(np.mean((interpolated - exact) ** 2)) / exact.mean()))
print("| budget | uniform: floor triangles | RMS error / mean | discontinuity: floor triangles | RMS error / mean |")
print("|---|---|---|---|---|")
for budget, (nu, eu), (nd, ed) in zip(args.budgets, *results.values()):
    print(f"| {budget:,} | {nu:,} | {eu:.3%} | {nd:,} | {ed:.3%} |")

fig, ax = plt.subplots(figsize=(6, 4.5), layout="constrained")
for (mesh, rows), marker in zip(results.items(), "os"):
    triangles, errors = np.array(rows).T
    ax.loglog(triangles, 100 * errors, marker=marker, label=f"{mesh} mesh")
ax.set(xlabel="triangles on the floor", ylabel="RMS error / mean radiosity (%)",
       title="Textbook floor, direct light: linear interpolation against exact")
ax.set_xticks(args.budgets, labels=[f"{b:,}" for b in args.budgets])
ax.xaxis.set_minor_formatter(NullFormatter())
ax.yaxis.set_major_formatter(StrMethodFormatter("{x:g}"))
ax.grid(True, which="both", alpha=0.3)
ax.legend()
fig.savefig(path, dpi=100)
print(f"wrote {path}")
