"""``penumbra.Solution``: a run's mesh and light as numpy arrays, whole and per surface."""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Any, Optional, Sequence, Union

import numpy as np

from . import _checks, _native
from ._scene import Scene


def _frozen(array: np.ndarray) -> np.ndarray:
    array.flags.writeable = False
    return array


class Discontinuities:
    """Discontinuity segments of the direct light: where its value (order 0), slope (1) or
    curvature (2) jumps on a surface.

    ``segments`` (K, 2, 3) float64 ends in scene coordinates; ``surface_id`` (K,) the surface
    each lies on; ``emitter`` (K,) the light whose light changes across it; ``event`` (K,) str:
    ``EV``, ``VE``, ``EEE``, ``contact``, ``blocker-EV`` or ``horizon``; ``boundary`` (K,) str:
    ``umbra`` (one side sees none of the light), ``penumbra`` (one side sees all of it) or
    ``inner``; ``order`` (K,) uint8. ``stats`` holds the search's figures when it came from
    :func:`penumbra.discontinuities`."""

    __slots__ = ("segments", "surface_id", "emitter", "event", "boundary", "order", "stats")

    def __init__(self, arrays: dict[str, Any], stats: Optional[dict[str, Any]] = None) -> None:
        self.segments: np.ndarray = _frozen(arrays["segments"])
        self.surface_id: np.ndarray = _frozen(arrays["surface_id"])
        self.emitter: np.ndarray = _frozen(arrays["emitter"])
        self.event: np.ndarray = _frozen(np.array(arrays["event"], dtype=str).reshape(-1))
        self.boundary: np.ndarray = _frozen(np.array(arrays["boundary"], dtype=str).reshape(-1))
        self.order: np.ndarray = _frozen(arrays["order"])
        self.stats: Optional[dict[str, Any]] = stats

    def slice(self, start: int, stop: int) -> "Discontinuities":
        """The segments from ``start`` up to ``stop``, as views."""
        return self._taking(slice(start, stop))

    def where(self, mask: np.ndarray) -> "Discontinuities":
        """The segments ``mask`` (a (K,) bool array) keeps, e.g. ``d.where(d.order == 0)``."""
        mask = np.asarray(mask, dtype=bool)
        if mask.shape != self.order.shape:
            raise ValueError(f"mask must have shape {self.order.shape}, not {mask.shape}")
        return self._taking(mask)

    def _taking(self, which: Any) -> "Discontinuities":
        taken = Discontinuities.__new__(Discontinuities)
        for name in ("segments", "surface_id", "emitter", "event", "boundary", "order"):
            setattr(taken, name, _frozen(getattr(self, name)[which]))
        taken.stats = self.stats
        return taken

    def __len__(self) -> int:
        return len(self.order)

    def __repr__(self) -> str:
        counts = ", ".join(f"{n} of order {o}" for o, n in zip(*np.unique(self.order, return_counts=True)))
        return f"<penumbra.Discontinuities: {len(self)} segments{': ' + counts if counts else ''}>"


class SurfaceSolution:
    """One surface of a :class:`Solution`: its mesh, with indices into its own ``vertices``,
    and its light; the arrays are views of the whole scene's (read-only)."""

    __slots__ = (
        "index", "name", "vertices", "triangles", "radiosity", "direct", "indirect",
        "irradiance", "direct_irradiance", "discontinuities", "_frame",
    )

    def __init__(
        self,
        solution: "Solution",
        index: int,
        name: str,
        frame: dict[str, np.ndarray],
        discontinuities: Discontinuities,
    ) -> None:
        v0, v1 = solution._vertex_offsets[index : index + 2]
        t0, t1 = solution._triangle_offsets[index : index + 2]
        self.index: int = index
        self.name: str = name
        self.vertices: np.ndarray = solution.vertices[v0:v1]
        self.triangles: np.ndarray = _frozen(solution.triangles[t0:t1] - np.uint32(v0))
        self.radiosity: np.ndarray = solution.radiosity[v0:v1]
        self.direct: np.ndarray = solution.direct[v0:v1]
        self.indirect: np.ndarray = solution.indirect[v0:v1]
        self.irradiance: np.ndarray = solution.irradiance[v0:v1]
        self.direct_irradiance: np.ndarray = solution.direct_irradiance[v0:v1]
        self._frame = frame
        self.discontinuities: Discontinuities = discontinuities

    @property
    def uv(self) -> np.ndarray:
        """(N, 2) float64: the vertices in the surface's plane frame (:meth:`Scene.frame`), for
        plots and 2D mesh tools."""
        return self.to_uv(self.vertices)

    def to_uv(self, points: Any) -> np.ndarray:
        """Points of the surface's plane, (N, 3), in its 2D frame: (N, 2)."""
        at = _checks.rows3(points, "points", allow_single=True) - self._frame["origin"]
        return np.column_stack([at @ self._frame["u"], at @ self._frame["v"]])

    def __repr__(self) -> str:
        return (
            f"<penumbra.SurfaceSolution {self.index} {self.name!r}: {len(self.vertices)} vertices, "
            f"{len(self.triangles)} triangles, {len(self.discontinuities)} discontinuity segments>"
        )


class Solution:
    """A run's result: the mesh of every surface and the light at its vertices.

    Whole-scene arrays, surface after surface in the scene's order (all read-only):

    - ``vertices`` (N, 3) float64, ``triangles`` (M, 3) uint32 (indices into ``vertices``,
      counter-clockwise seen from the surface's front), ``surface_id`` (N,) uint32 per vertex,
      ``triangle_surface_id`` (M,) uint32;
    - ``radiosity`` (N, 3) float64: B in W/m² per channel, the surface's own emission included,
      equal to the bit to ``solution.json``'s;
    - ``direct`` (N, 3): the light reflected straight from the lights, ρ·H_direct (exact);
      ``indirect`` (N, 3): the light reflected after more bounces, ρ·(H − H_direct); so
      ``radiosity = emission + direct + indirect`` (to rounding). ``irradiance`` (N, 3): the
      irradiance H arriving at each vertex, and ``direct_irradiance`` (N, 3) its part straight
      from the lights, H_direct (which ``direct`` loses where ρ is 0);
    - ``discontinuities``: the segments built into the mesh (:class:`Discontinuities`).

    ``surfaces`` (or ``solution[name]``) gives the same per surface. ``report`` is
    ``report.json`` as a dict; ``partial`` says the run stopped early (time budget, interrupt)
    with the best solution so far; :meth:`write` writes the command line's files."""

    def __init__(self, native: _native.RunOutput) -> None:
        self._native = native
        arrays = native.arrays()
        self.scene: Scene = Scene(native.scene)
        self.vertices: np.ndarray = _frozen(arrays["vertices"])
        self.triangles: np.ndarray = _frozen(arrays["triangles"])
        self.surface_id: np.ndarray = _frozen(arrays["surface_id"])
        self.triangle_surface_id: np.ndarray = _frozen(arrays["triangle_surface_id"])
        self.radiosity: np.ndarray = _frozen(arrays["radiosity"])
        self.direct: np.ndarray = _frozen(arrays["direct"])
        self.indirect: np.ndarray = _frozen(arrays["indirect"])
        self.irradiance: np.ndarray = _frozen(arrays["irradiance"])
        self.direct_irradiance: np.ndarray = _frozen(arrays["direct_irradiance"])
        self.discontinuities: Discontinuities = Discontinuities(arrays["discontinuities"])
        self._vertex_offsets = arrays["vertex_offsets"]
        self._triangle_offsets = arrays["triangle_offsets"]
        self.report: dict[str, Any] = json.loads(native.report_json())
        self._surfaces: Optional[list[SurfaceSolution]] = None

    @property
    def partial(self) -> bool:
        """Whether the run stopped early (a time budget, an interrupt) and this is the best
        solution it had."""
        return bool(self.report["partial"])

    @property
    def surfaces(self) -> list[SurfaceSolution]:
        """One :class:`SurfaceSolution` per surface, in the scene's order."""
        if self._surfaces is None:
            count = len(self.scene)
            names, frames = self.scene.surface_names, self.scene._frames()
            # Segments come surface after surface: each surface's are one slice.
            d = self.discontinuities
            bounds = np.searchsorted(d.surface_id, np.arange(count + 1))

            def segments_of(i: int) -> Discontinuities:
                return d.slice(bounds[i], bounds[i + 1])

            self._surfaces = [
                SurfaceSolution(self, i, names[i], frames[i], segments_of(i)) for i in range(count)
            ]
        return self._surfaces

    def __getitem__(self, key: Union[int, str]) -> SurfaceSolution:
        """A surface by index or by name."""
        if isinstance(key, str):
            key = self.scene.surface_id(key)
        if isinstance(key, bool) or not isinstance(key, (int, np.integer)):
            raise TypeError(f"surfaces are found by index or name, not {type(key).__name__}")
        return self.surfaces[key]

    def interpolate(
        self,
        points: Any,
        *,
        surfaces: Any = None,
        quantity: str = "radiosity",
    ) -> np.ndarray:
        """The solution between its vertices: ``quantity`` (``"radiosity"``, ``"direct"``,
        ``"indirect"``, ``"irradiance"`` or ``"direct_irradiance"``) at ``points`` (N, 3), linear over the triangle of
        the mesh that holds each point, as ``penumbra sweep`` measures a mesh's error. Returns
        (N, 3) float64, NaN for points on no surface (or off the surface given for them).

        ``surfaces`` (N,) gives each point's surface (-1: none); by default it is found
        (:meth:`Scene.locate`). Against :func:`penumbra.direct_light` this measures the error
        of a mesh's interpolation of the exact direct light::

            >>> import numpy as np, penumbra
            >>> scene = penumbra.Scene.builtin("textbook")
            >>> solution = penumbra.run(scene, direct_only=True, max_elements=2000)
            >>> points = np.array([[0.8, 0.1, 0.0], [1.5, -2.0, 0.0]])
            >>> exact = scene.reflectance[scene.surface_id("floor")] * penumbra.direct_light(
            ...     scene, points, [0, 0, 1])
            >>> bool(np.abs(solution.interpolate(points) - exact).max() < 0.01 * exact.max())
            True
        """
        at = _checks.rows3(points, "points", allow_single=True)
        ids = _checks.surface_ids(surfaces, "surfaces", len(at), len(self.scene))
        if ids is None:
            ids = self.scene.locate(at).tolist()
        _checks.choice(
            quantity, "quantity", ("radiosity", "direct", "indirect", "irradiance", "direct_irradiance")
        )
        return self._native.interpolate(at, ids, quantity)

    @property
    def triangle_count(self) -> int:
        return len(self.triangles)

    def render(self) -> np.ndarray:
        """The image from the scene's camera, as ``render.png`` holds it: (height, width, 3)
        uint8 sRGB."""
        return self._native.render()

    def solution_json(self) -> str:
        """``solution.json``, as text."""
        return self._native.solution_json()

    def write(
        self,
        directory: Union[str, "os.PathLike[str]"],
        *,
        svg: Union[str, Sequence[str]] = "auto",
        convergence: bool = False,
        export: Union[str, Sequence[str]] = "html",
    ) -> list[Path]:
        """Writes the files ``penumbra run`` writes into ``directory`` (created if needed), all or
        nothing: ``solution.json``, ``report.json``, ``render.png`` and SVGs of the surfaces
        ``svg`` chooses (``"auto"``, ``"all"``, ``"none"`` or a list of names) in
        ``surfaces/``; with ``convergence``, the solver's residual history too; and the exports
        ``export`` names, as ``--export`` does: any of ``"vtp"``, ``"ply"``, ``"glb"``,
        ``"obj"``, ``"html"`` (the viewer page, ``index.html``, written by default), ``"all"``
        or ``"none"``, as a list or comma-separated. Returns the paths written."""
        if not isinstance(directory, (str, os.PathLike)):
            raise TypeError(f"directory must be a str or a path, not {type(directory).__name__}")
        if not isinstance(svg, str):
            if not isinstance(svg, (list, tuple)) or not all(isinstance(n, str) for n in svg):
                raise TypeError('svg must be "auto", "all", "none" or a list of surface names')
            svg = list(svg)
        if not isinstance(export, str):
            if not isinstance(export, (list, tuple)) or not all(isinstance(n, str) for n in export):
                raise TypeError('export must be format names ("vtp", "html", ...) as a list or a string')
            export = ",".join(export)
        native = self._native.write(os.fspath(directory), svg, bool(convergence), export)
        return [Path(p) for p in native]

    def __repr__(self) -> str:
        method = self.report.get("method", {})
        solver = "none (direct light only)" if method.get("direct_only") else method.get("solver", "?")
        return (
            f"<penumbra.Solution of {self.scene.name!r}: {len(self.vertices)} vertices, "
            f"{len(self.triangles)} triangles, {len(self.discontinuities)} discontinuity segments, "
            f"solver {solver}{', partial' if self.partial else ''}>"
        )
