"""The Cornell box's floor: its radiosity, and the discontinuity lines its mesh follows.

Runs the built-in Cornell box as `penumbra run cornell` does (default options: discontinuity
mesh, hierarchical solver) and draws the floor seen from above, back wall at the top: the
radiosity at the mesh's vertices (mean of the three channels, W/m²), Gouraud-shaded over its
triangles, and the discontinuity segments built into the mesh, coloured by order: 0 where the
direct light's value jumps (the blocks' contact lines), 1 where its slope jumps, 2 where its
curvature does. Prints the segments by order and event. About 4 s on 2 cores.

    python python/examples/floor_radiosity.py --out docs/python-floor.png
"""

import argparse
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
from matplotlib.collections import LineCollection
from matplotlib.tri import Triangulation

import penumbra


def png_path(out: str, name: str) -> Path:
    """``out`` itself, or ``out/name`` when ``out`` is a directory."""
    path = Path(out) / name if Path(out).is_dir() or out.endswith("/") else Path(out)
    path.parent.mkdir(parents=True, exist_ok=True)
    return path


parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
parser.add_argument("--out", default=".", help="PNG file, or directory for floor_radiosity.png")
path = png_path(parser.parse_args().out, "floor_radiosity.png")

scene = penumbra.Scene.builtin("cornell")
solution = penumbra.run(scene)
floor = solution["floor"]
# The floor is the plane y = 0 (millimetres), facing +y: its 2D coordinates are x and z.
assert np.allclose(scene.normals[floor.index], [0, 1, 0]) and not floor.vertices[:, 1].any()
x, z = floor.vertices[:, 0], floor.vertices[:, 2]
mesh = Triangulation(x, z, floor.triangles)

fig, ax = plt.subplots(figsize=(6.8, 6), layout="constrained")
shading = ax.tripcolor(mesh, floor.radiosity.mean(axis=1), shading="gouraud", cmap="gray")
fig.colorbar(shading, ax=ax, label="radiosity, mean of R, G, B (W/m²)", shrink=0.8)
d = floor.discontinuities
styles = {0: ("tab:red", "value"), 1: ("tab:orange", "slope"), 2: ("tab:cyan", "curvature")}
for order, (colour, what) in styles.items():
    lines = d.segments[d.order == order][:, :, [0, 2]]
    ax.add_collection(LineCollection(lines, colors=colour, linewidths=1.2,
                                     label=f"order {order}: {what} jumps ({len(lines)})"))
fig.legend(loc="outside lower center", ncols=3, fontsize=8, frameon=False)
ax.set_aspect("equal")
ax.invert_xaxis()  # seen from above, with the back wall (z = 559.2) at the top
ax.set_xlabel("x (mm)")
ax.set_ylabel("z (mm)")
ax.set_title(f"Cornell box floor: {len(floor.triangles):,} triangles, "
             f"{len(d)} discontinuity segments")
fig.savefig(path, dpi=100)

print("order  " + "  ".join(f"{e:>8}" for e in np.unique(d.event)))
for order in np.unique(d.order):
    counts = [int(((d.order == order) & (d.event == e)).sum()) for e in np.unique(d.event)]
    print(f"{order:>5}  " + "  ".join(f"{c:>8}" for c in counts))
print(f"wrote {path}")
