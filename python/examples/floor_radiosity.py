"""The Cornell box's floor: its radiosity, and the discontinuity lines its mesh follows.

Runs the built-in Cornell box as `penumbra run cornell` does (default options: discontinuity
mesh, hierarchical solver) and draws the floor seen from above, back wall at the top, in the
floor's own 2D frame (`SurfaceSolution.uv`): the radiosity at the mesh's vertices (mean of the
three channels, W/m²), Gouraud-shaded over its triangles, and the discontinuity segments built
into the mesh, coloured by order: 0 where the direct light's value jumps (the blocks' contact
lines), 1 where its slope jumps, 2 where its curvature does. Prints the segments by order and
event. About 4 s on 2 cores.

    python python/examples/floor_radiosity.py --out docs/python-floor.png
"""

import argparse
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
from matplotlib.collections import LineCollection

import penumbra

parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
parser.add_argument("--out", type=Path, default=Path("."), metavar="DIR",
                    help="directory for floor_radiosity.png, or a .png file")
out = parser.parse_args().out
path = out if out.suffix == ".png" else out / "floor_radiosity.png"
path.parent.mkdir(parents=True, exist_ok=True)

solution = penumbra.run(penumbra.Scene.builtin("cornell"))
floor = solution["floor"]
d = floor.discontinuities
# The floor's frame (scene.frame("floor")) starts at its back corner by the red wall, u towards
# the front, v towards the green wall (both in mm). Plotting v across and u down (the y axis
# inverted) shows the floor from above as the camera sees the box: back wall at the top.
u, v = floor.uv.T
lines = floor.to_uv(d.segments.reshape(-1, 3)).reshape(-1, 2, 2)[:, :, ::-1]  # (v, u) ends

fig, ax = plt.subplots(figsize=(6.8, 6), layout="constrained")
shading = ax.tripcolor(v, u, floor.triangles, floor.radiosity.mean(axis=1), shading="gouraud",
                       cmap="gray")
fig.colorbar(shading, ax=ax, label="radiosity, mean of R, G, B (W/m²)", shrink=0.8)
styles = {0: ("tab:red", "value"), 1: ("tab:orange", "slope"), 2: ("tab:cyan", "curvature")}
for order, (colour, what) in styles.items():
    these = lines[d.order == order]
    ax.add_collection(LineCollection(these, colors=colour, linewidths=1.2,
                                     label=f"order {order}: {what} jumps ({len(these)})"))
fig.legend(loc="outside lower center", ncols=3, fontsize=8, frameon=False)
ax.set_aspect("equal")
ax.invert_yaxis()  # u = 0, the back wall, at the top
ax.set(xlabel="v (mm): from the red wall", ylabel="u (mm): from the back wall",
       title=f"Cornell box floor: {len(floor.triangles):,} triangles, "
             f"{len(d)} discontinuity segments")
fig.savefig(path, dpi=100)

events = np.unique(d.event)
print("order  " + "  ".join(f"{e:>8}" for e in events))
for order in np.unique(d.order):
    counts = [int(((d.order == order) & (d.event == e)).sum()) for e in events]
    print(f"{order:>5}  " + "  ".join(f"{c:>8}" for c in counts))
print(f"wrote {path}")
