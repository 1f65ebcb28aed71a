"""The research primitives: the exact direct light at any points, the discontinuities without a
mesh, and path-traced references."""

from __future__ import annotations

from typing import Any, Literal, NamedTuple, Optional

import numpy as np

from . import _checks, _native
from ._scene import Scene
from ._solution import Discontinuities


def _scene(scene: Any) -> Scene:
    if not isinstance(scene, Scene):
        raise TypeError(f"scene must be a penumbra.Scene, not {type(scene).__name__}")
    return scene


def direct_light(
    scene: Scene,
    points: Any,
    normals: Any,
    *,
    surfaces: Any = None,
    threads: Optional[int] = None,
) -> np.ndarray:
    """The exact direct irradiance H (W/m² per channel) at ``points`` facing ``normals``: an
    (N, 3) float64 array. No sampling: at each point penumbra finds the part of every light the
    point sees (backprojection through the occluders) and integrates it in closed form
    (Lambert's contour formula).

    ``points`` (N, 3); ``normals`` (N, 3), or one (3,) normal for all (need not be unit).
    ``surfaces`` (N,) ints: the surface each point lies on, whose own polygon casts no shadow
    on it (-1: a point free in space); by default each point's surface is found
    (:meth:`Scene.locate`). The radiosity a surface sends back is ``emission + reflectance * H``.

    Example: under the centre of a unit square light of exitance E at height d, H = E (4/π) r
    atan r with r = x/√(1 + x²), x = 1/(2d)::

        >>> import numpy as np, penumbra
        >>> light = [[-0.5, -0.5, 1], [-0.5, 0.5, 1], [0.5, 0.5, 1], [0.5, -0.5, 1]]
        >>> floor = [[-4, -4, 0], [4, -4, 0], [4, 4, 0], [-4, 4, 0]]
        >>> scene = penumbra.Scene.from_polygons([light, floor], reflectance=[[0] * 3, [0.5] * 3],
        ...                                      emission=[[10] * 3, [0] * 3])
        >>> h = penumbra.direct_light(scene, [[0, 0, 0]], [0, 0, 1])
        >>> r = 0.5 / np.sqrt(1.25)
        >>> bool(abs(h[0, 0] - 10 * 4 / np.pi * r * np.arctan(r)) < 1e-12)
        True
    """
    scene = _scene(scene)
    at = _checks.rows3(points, "points")
    facing = _checks.normals(normals, "normals", len(at))
    largest = np.abs(facing).max(axis=1, initial=0.0)
    if not (largest > 0).all():
        raise ValueError("normals: every normal needs a direction (a zero row has none)")
    facing = facing / largest[:, None]  # the same directions, of lengths the native side can square
    ids = _checks.surface_ids(surfaces, "surfaces", len(at), len(scene))
    return _native.direct_light(
        scene._native, at, facing, ids, _checks.count(threads, "threads")
    )


def discontinuities(
    scene: Scene,
    *,
    eee: bool = True,
    events: Literal["complete", "extremal"] = "complete",
    event_tol: Optional[float] = None,
    max_elements: Optional[int] = None,
    threads: Optional[int] = None,
) -> Discontinuities:
    """The discontinuities of the direct light on every surface, without meshing: the lines
    where its value, slope or curvature jumps (EV, VE and EEE events, contact lines).

    ``eee``, ``events`` and ``event_tol`` are :func:`run`'s. With ``max_elements``, receivers
    and shadows too small for a mesh of that many triangles get no events, as in a run of that
    budget; without it, none is left out for its size. ``stats`` on the result holds the
    search's figures (pairs searched, wedges, segments by event and order)."""
    scene = _scene(scene)
    found = _native.discontinuities(
        scene._native,
        _checks.flag(eee, "eee"),
        _checks.choice(events, "events", ("complete", "extremal")) or "complete",
        _checks.number(event_tol, "event_tol"),
        _checks.count(max_elements, "max_elements"),
        _checks.count(threads, "threads"),
    )
    stats = found.pop("stats")
    return Discontinuities(found, stats)


class Reference(NamedTuple):
    """Path-traced radiosity and the standard error of each value's channel mean."""

    radiosity: np.ndarray
    standard_error: np.ndarray


def reference(
    scene: Scene,
    points: Any,
    *,
    surfaces: Any = None,
    paths: Optional[int] = 4096,
    seed: Optional[int] = 1,
    threads: Optional[int] = None,
) -> Reference:
    """A Monte Carlo reference for full (multi-bounce) solutions: the radiosity B (W/m² per
    channel) at each of ``points`` by path tracing, with the exact direct light at every bounce
    and Russian roulette. Returns ``(radiosity (N, 3), standard_error (N,))``.

    Each point lies on a surface: ``surfaces`` (N,) gives it, or it is found
    (:meth:`Scene.locate`; a point on no surface is a ``ValueError``). ``paths`` per point
    (stratified in 16 batches, whose spread gives the standard error); every point has its own
    random stream from ``seed``, so results do not depend on ``threads``."""
    scene = _scene(scene)
    at = _checks.rows3(points, "points")
    ids = _checks.surface_ids(surfaces, "surfaces", len(at), len(scene))
    radiosity, error = _native.reference(
        scene._native,
        at,
        ids,
        4096 if paths is None else _checks.whole(paths, "paths"),
        1 if seed is None else _checks.whole(seed, "seed", minimum=0),
        _checks.count(threads, "threads"),
    )
    return Reference(radiosity, error)
