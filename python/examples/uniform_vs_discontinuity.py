"""Uniform against discontinuity meshes: the error of linear interpolation on the textbook floor.

Runs the built-in textbook scene (a unit square light at height 3, a unit square blocker at
height 1, a 6 x 6 floor at z = 0) with `direct_only=True`, which makes the radiosity at every
vertex exact, on uniform and discontinuity meshes at several element budgets. What is left is
the error of interpolating linearly between the vertices: at 20,000 random points on the floor,
the radiosity interpolated over the floor's triangles (`Solution.interpolate`) against the exact
value, emission + reflectance x `penumbra.direct_light`. Plots and prints the RMS error relative
to the mean exact radiosity against the floor's triangles. About 1 s on 2 cores.

    python python/examples/uniform_vs_discontinuity.py --out docs/python-meshes.png
"""

import argparse
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
from matplotlib.ticker import NullFormatter, StrMethodFormatter

import penumbra

parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
parser.add_argument("--out", type=Path, default=Path("."), metavar="DIR",
                    help="directory for uniform_vs_discontinuity.png, or a .png file")
parser.add_argument("--budgets", type=int, nargs="+", default=[500, 1000, 2000, 4000, 8000],
                    help="max_elements of each run, for the whole scene")
args = parser.parse_args()
path = args.out if args.out.suffix == ".png" else args.out / "uniform_vs_discontinuity.png"
path.parent.mkdir(parents=True, exist_ok=True)

scene = penumbra.Scene.builtin("textbook")
f = scene.surface_id("floor")
corners = scene.polygons[f]  # the square [-3, 3]^2 in the plane z = 0, facing +z
assert np.allclose(scene.normals[f], [0, 0, 1]) and not corners[:, 2].any()
xy = np.random.default_rng(1).uniform(corners.min(axis=0)[:2], corners.max(axis=0)[:2], (20_000, 2))
points, on_floor = np.c_[xy, np.zeros(len(xy))], np.full(len(xy), f)
exact = (scene.emission[f] + scene.reflectance[f] * penumbra.direct_light(
    scene, points, [0, 0, 1], surfaces=on_floor)).mean(axis=1)

results = {"uniform": [], "discontinuity": []}  # (floor triangles, RMS error / mean) per budget
for budget in args.budgets:
    for mesh, rows in results.items():
        solution = penumbra.run(scene, mesh=mesh, max_elements=budget, direct_only=True)
        # Linear over the mesh's triangles, as `penumbra sweep` measures a mesh's error.
        interpolated = solution.interpolate(points, surfaces=on_floor).mean(axis=1)
        error = np.sqrt(np.mean((interpolated - exact) ** 2)) / exact.mean()
        rows.append((len(solution["floor"].triangles), error))
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
