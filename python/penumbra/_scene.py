"""``penumbra.Scene``: a validated scene of planar polygons, some of them lights."""

from __future__ import annotations

import os
from typing import Any, Mapping, Optional, Sequence, Union

import numpy as np

from . import _checks, _native

SceneSource = Union[str, "os.PathLike[str]"]


class Scene:
    """A diffuse scene of planar polygons lit by the polygons that emit, validated.

    Make one with :meth:`load` (a ``.json`` or ``.obj`` file), :meth:`builtin` (a built-in
    scene, see :func:`penumbra.builtin_scenes`), :meth:`from_polygons` (arrays) or
    :meth:`from_json` (text). Every constructor validates: a scene that is not valid raises
    :class:`penumbra.SceneError`, whose ``problems`` list every problem at once.

    Example::

        >>> import penumbra
        >>> scene = penumbra.Scene.from_polygons(
        ...     [[[-0.5, -0.5, 2], [-0.5, 0.5, 2], [0.5, 0.5, 2], [0.5, -0.5, 2]],
        ...      [[-2, -2, 0], [2, -2, 0], [2, 2, 0], [-2, 2, 0]]],
        ...     names=["light", "floor"],
        ...     reflectance=[[0, 0, 0], [0.7, 0.7, 0.7]],
        ...     emission=[[10, 10, 10], [0, 0, 0]])
        >>> len(scene), scene.surface_names
        (2, ['light', 'floor'])
    """

    __slots__ = ("_native", "_names", "_frame_list")

    def __init__(self, native: _native.Scene) -> None:
        if not isinstance(native, _native.Scene):
            raise TypeError(
                "make a Scene with Scene.load, Scene.builtin, Scene.from_polygons or Scene.from_json"
            )
        self._native = native
        self._names: Optional[list[str]] = None
        self._frame_list: Optional[list[dict[str, np.ndarray]]] = None

    def _frames(self) -> list[dict[str, np.ndarray]]:
        """Every surface's frame (see :meth:`frame`), made once."""
        if self._frame_list is None:
            frames = []
            for i, rows in enumerate(self._native.frames):
                if rows is None:  # validation refuses polygons without a plane
                    raise ValueError(f"surface {i} has no plane")
                frames.append(dict(zip(("origin", "u", "v", "normal"), rows)))
            self._frame_list = frames
        return self._frame_list

    @staticmethod
    def load(path: SceneSource, *, merge: bool = True) -> "Scene":
        """Reads a ``.json`` scene or an ``.obj`` file (with its ``.mtl`` libraries; ``Ke`` makes
        a material emit). ``merge=False`` keeps every OBJ face as its own surface instead of
        merging coplanar adjacent faces of one material.

        Raises ``FileNotFoundError`` for a missing file and :class:`penumbra.SceneError` for one
        that is not a valid scene."""
        if not isinstance(path, (str, os.PathLike)):
            raise TypeError(f"path must be a str or a path, not {type(path).__name__}")
        return Scene(_native.Scene.load(os.fspath(path), _checks.flag(merge, "merge")))

    @staticmethod
    def builtin(name: str) -> "Scene":
        """The built-in scene called ``name``: ``"cornell"``, ``"textbook"``, ``"furnace"``...
        (:func:`penumbra.builtin_scenes` lists them)."""
        if not isinstance(name, str):
            raise TypeError(f"name must be a string, not {type(name).__name__}")
        return Scene(_native.Scene.builtin(name))

    @staticmethod
    def from_json(text: str) -> "Scene":
        """A scene in penumbra's JSON format (``docs/scene-format.md``), given as text."""
        if not isinstance(text, str):
            raise TypeError(f"text must be a string, not {type(text).__name__}")
        return Scene(_native.Scene.from_json(text))

    @staticmethod
    def from_polygons(
        polygons: Sequence[Any],
        *,
        reflectance: Any,
        emission: Any = None,
        names: Optional[Sequence[str]] = None,
        name: str = "scene",
        camera: Optional[Mapping[str, Any]] = None,
    ) -> "Scene":
        """A scene from its polygons.

        ``polygons``: one (K, 3) array-like of corners per surface, counter-clockwise seen from
        the surface's front (light leaves and arrives on the front). ``reflectance``: (S, 3)
        per surface and channel in [0, 1), or one (3,) colour for all. ``emission``: (S, 3)
        exitance in W/m² (default: none emits). ``names``: one per surface, unique (default
        ``surface-0``, ``surface-1``...). ``camera``: ``{"eye": ..., "target": ..., "up": ...,
        "fov_deg": ...}`` for renders (``up`` defaults to +z, ``fov_deg`` to 45)."""
        if isinstance(polygons, np.ndarray) and polygons.ndim == 3:
            polygons = list(polygons)
        if not isinstance(polygons, (list, tuple)):
            raise TypeError(
                f"polygons must be a list of (K, 3) arrays, not {type(polygons).__name__}"
            )
        corners = [_checks.rows3(p, f"polygons[{i}]") for i, p in enumerate(polygons)]
        count = len(corners)
        if names is None:
            names = [f"surface-{i}" for i in range(count)]
        if isinstance(names, str) or not all(isinstance(n, str) for n in names):
            raise TypeError("names must be a list of strings")
        if len(names) != count:
            raise ValueError(f"names has {len(names)} entries for {count} polygons")
        if not isinstance(name, str):
            raise TypeError(f"name must be a string, not {type(name).__name__}")
        rho = _per_surface(reflectance, "reflectance", count)
        exitance = _per_surface(0.0 if emission is None else emission, "emission", count)
        stacked = np.concatenate(corners) if corners else np.zeros((0, 3))
        return Scene(
            _native.Scene.from_arrays(
                name,
                list(names),
                stacked,
                [len(c) for c in corners],
                rho,
                exitance,
                None if camera is None else _camera(camera),
            )
        )

    def to_json(self) -> str:
        """The scene in penumbra's JSON format; :meth:`from_json` reads it back equal."""
        return self._native.to_json()

    def locate(self, points: Any, normals: Any = None) -> np.ndarray:
        """The surface each point lies on (within the scene's contact distance), -1 where none:
        an (N,) int64 array. Where several surfaces meet at a point, the one whose normal is
        closest to the point's normal (if given), else the first."""
        at = _checks.rows3(points, "points", allow_single=True)
        facing = None if normals is None else _checks.normals(normals, "normals", len(at))
        return _native.locate(self._native, at, facing)

    def with_camera(
        self,
        eye: Any = None,
        target: Any = None,
        up: Any = None,
        fov_deg: Optional[float] = None,
    ) -> "Scene":
        """The same scene seen through another camera (for :meth:`Solution.render` and
        ``render.png``). Each part given replaces that part of the scene's camera, or of the
        default view that frames the whole scene, as ``penumbra run --eye --target --up --fov``
        do. Raises :class:`penumbra.SceneError` for a camera that cannot make a picture."""

        def point(value: Any, name: str) -> Optional[tuple[float, float, float]]:
            if value is None:
                return None
            row = _checks.rows3(value, name, allow_single=True)
            if len(row) != 1:
                raise ValueError(f"{name} must be one point, not {len(row)}")
            x, y, z = row[0].tolist()
            return (x, y, z)

        return Scene(
            self._native.with_camera(
                point(eye, "eye"),
                point(target, "target"),
                point(up, "up"),
                _checks.number(fov_deg, "fov_deg", positive=True),
            )
        )

    def frame(self, surface: Union[int, str]) -> dict[str, np.ndarray]:
        """Surface ``surface``'s plane frame (by index or name): ``origin`` and the unit vectors
        ``u``, ``v`` (in the plane) and ``normal``, each (3,). A point p of the plane has 2D
        coordinates ``((p - origin) @ u, (p - origin) @ v)``; :attr:`SurfaceSolution.uv` gives
        them for a solution's vertices."""
        index = self.surface_id(surface) if isinstance(surface, str) else surface
        if isinstance(index, bool) or not isinstance(index, (int, np.integer)):
            raise TypeError(f"surface must be an index or a name, not {type(surface).__name__}")
        frames = self._frames()
        if not -len(frames) <= index < len(frames):
            raise IndexError(f"surface {index} out of range: the scene has {len(frames)}")
        return {key: value.copy() for key, value in frames[index].items()}

    def surface_id(self, name: str) -> int:
        """The index of the surface called ``name``."""
        if self._names is None:
            self._names = self._native.surface_names
        try:
            return self._names.index(name)
        except ValueError:
            raise KeyError(f"the scene has no surface named {name!r}") from None

    @property
    def name(self) -> str:
        return self._native.name

    @property
    def source(self) -> str:
        """Where the scene came from: a path, ``builtin:NAME``, ``json`` or ``python``."""
        return self._native.source

    @property
    def warnings(self) -> list[str]:
        """What loading repaired (OBJ files), one line each."""
        return self._native.warnings

    @property
    def surface_names(self) -> list[str]:
        if self._names is None:
            self._names = self._native.surface_names
        return list(self._names)

    @property
    def polygons(self) -> list[np.ndarray]:
        """Each surface's corners, a (K, 3) float64 array."""
        return self._native.polygons

    @property
    def reflectance(self) -> np.ndarray:
        """(S, 3) float64: each surface's diffuse reflectance per channel."""
        return self._native.reflectance

    @property
    def emission(self) -> np.ndarray:
        """(S, 3) float64: each surface's exitance per channel, in W/m²."""
        return self._native.emission

    @property
    def normals(self) -> np.ndarray:
        """(S, 3) float64: each surface's unit normal (its front)."""
        return self._native.normals

    @property
    def areas(self) -> np.ndarray:
        """(S,) float64: each surface's area, in scene units squared."""
        return np.asarray(self._native.areas)

    @property
    def camera(self) -> Optional[dict[str, Any]]:
        """The scene's camera, if it has one: ``eye``, ``target``, ``up``, ``fov_deg``."""
        camera = self._native.camera
        if camera is None:
            return None
        eye, target, up, fov = camera
        return {"eye": eye, "target": target, "up": up, "fov_deg": fov}

    @property
    def fingerprint(self) -> str:
        """A hash of the whole scene (its JSON form: names, geometry, materials, camera), as
        ``report.json`` records it."""
        return self._native.fingerprint

    def __len__(self) -> int:
        return len(self._native)

    def __eq__(self, other: object) -> bool:
        return isinstance(other, Scene) and self._native == other._native

    __hash__ = None  # type: ignore[assignment]

    def __repr__(self) -> str:
        emitters = int((self.emission.max(axis=1) > 0).sum())
        return (
            f"<penumbra.Scene {self.name!r}: {len(self)} surfaces, {emitters} emitting, "
            f"from {self.source}>"
        )


def _per_surface(value: Any, name: str, count: int) -> np.ndarray:
    """(count, 3) from (count, 3), or one (3,) colour (or a number) for every surface."""
    array = np.asarray(value)
    if array.dtype.kind not in "iuf":
        raise TypeError(f"{name} must hold real numbers, not {array.dtype}")
    if array.ndim == 0:
        array = np.full((count, 3), float(array))
    elif array.shape == (3,):
        array = np.tile(array.astype(np.float64), (count, 1))
    array = _checks.rows3(array, name)
    if len(array) != count:
        raise ValueError(f"{name} has {len(array)} rows for {count} polygons")
    return array


def _camera(camera: Mapping[str, Any]) -> tuple[Any, ...]:
    """(eye, target, up, fov_deg) from a camera dict, checked."""
    if not isinstance(camera, Mapping):
        raise TypeError(f"camera must be a dict, not {type(camera).__name__}")
    unknown = set(camera) - {"eye", "target", "up", "fov_deg"}
    if unknown:
        raise ValueError(f"camera has unknown keys {sorted(unknown)}; it takes eye, target, up, fov_deg")
    for key in ("eye", "target"):
        if key not in camera:
            raise ValueError(f"camera needs {key!r}")

    def point(key: str, default: Any = None) -> tuple[float, float, float]:
        row = _checks.rows3(camera.get(key, default), f"camera[{key!r}]", allow_single=True)
        if len(row) != 1:
            raise ValueError(f"camera[{key!r}] must be one point, not {len(row)}")
        x, y, z = row[0].tolist()
        return (x, y, z)

    fov = _checks.number(camera.get("fov_deg", 45.0), "camera['fov_deg']", positive=True)
    return (point("eye"), point("target"), point("up", (0.0, 0.0, 1.0)), fov)
