"""penumbra: discontinuity meshing and radiosity for diffuse scenes of planar polygons lit by
polygonal area lights, from numpy.

The direct light is exact (backprojection and Lambert's contour formula); the mesh follows the
lines where the light's value, slope or curvature jumps; every approximation can be measured
against an exact or path-traced reference.

- :class:`Scene`: ``Scene.load(path)``, ``Scene.builtin(name)``, ``Scene.from_polygons(...)``;
- :func:`run` meshes, lights and solves a scene as ``penumbra run`` does, and returns a
  :class:`Solution`: numpy arrays of vertices, triangles, radiosity, its direct and indirect
  parts, and the discontinuity segments, whole and per surface;
- :func:`direct_light` (the exact direct irradiance at any points), :func:`discontinuities`
  (without meshing) and :func:`reference` (path-traced values with standard errors).

Example::

    >>> import penumbra
    >>> solution = penumbra.run(penumbra.Scene.builtin("textbook"), direct_only=True,
    ...                         max_elements=2000)
    >>> solution.radiosity.shape[1], solution["floor"].name
    (3, 'floor')

Errors: :class:`SceneError` (a ``ValueError``) for scenes that are not valid, with every
problem in ``problems``; ``ValueError`` or ``TypeError`` naming the argument for bad
arguments; :class:`RunInterrupted` (a ``KeyboardInterrupt``) for Ctrl-C, carrying the partial
solution; :class:`RunCancelled` (a ``RuntimeError``) when an :class:`Interrupt` stops a run
before any solution exists.
"""

from __future__ import annotations

from . import _native
from ._native import SceneError
from ._research import Reference, direct_light, discontinuities, reference
from ._run import Interrupt, RunCancelled, RunInterrupted, run
from ._scene import Scene
from ._solution import Discontinuities, Solution, SurfaceSolution

__version__: str = _native.__version__


def builtin_scenes() -> dict[str, str]:
    """The built-in scenes' names and one-line descriptions, for :meth:`Scene.builtin`."""
    return dict(_native.builtin_scenes())


__all__ = [
    "Discontinuities",
    "Interrupt",
    "Reference",
    "RunCancelled",
    "RunInterrupted",
    "Scene",
    "SceneError",
    "Solution",
    "SurfaceSolution",
    "builtin_scenes",
    "direct_light",
    "discontinuities",
    "reference",
    "run",
    "__version__",
]
