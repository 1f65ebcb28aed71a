"""Type stubs of penumbra's native module (the Rust half). Use the public API in `penumbra`."""

from pathlib import Path
from typing import Any, Callable, Optional, Union, final

import numpy as np

__all__ = [
    "SceneError",
    "__version__",
    "Scene",
    "Interrupt",
    "RunOutput",
    "builtin_scenes",
    "run",
    "direct_light",
    "discontinuities",
    "reference",
    "locate",
]

__version__: str

class SceneError(ValueError):
    """A scene that cannot be read or is not valid."""

    problems: list[str]
    """Every problem validation found, as `penumbra check` reports them."""
    warnings: list[str]
    """What loading repaired first (OBJ files), one line each."""

@final
class Scene:
    @staticmethod
    def load(path: str, merge: bool = True) -> Scene: ...
    @staticmethod
    def builtin(name: str) -> Scene: ...
    @staticmethod
    def from_json(text: str) -> Scene: ...
    @staticmethod
    def from_arrays(
        name: str,
        names: list[str],
        corners: np.ndarray,
        counts: list[int],
        reflectance: np.ndarray,
        emission: np.ndarray,
        camera: Optional[tuple[Any, ...]] = None,
    ) -> Scene: ...
    def to_json(self) -> str: ...
    @property
    def name(self) -> str: ...
    @property
    def source(self) -> str: ...
    @property
    def warnings(self) -> list[str]: ...
    @property
    def surface_names(self) -> list[str]: ...
    @property
    def polygons(self) -> list[np.ndarray]: ...
    @property
    def reflectance(self) -> np.ndarray: ...
    @property
    def emission(self) -> np.ndarray: ...
    @property
    def normals(self) -> np.ndarray: ...
    @property
    def areas(self) -> list[float]: ...
    @property
    def camera(
        self,
    ) -> Optional[tuple[list[float], list[float], list[float], float]]: ...
    @property
    def frames(self) -> list[Optional[np.ndarray]]: ...
    def with_camera(
        self,
        eye: Optional[tuple[float, float, float]] = None,
        target: Optional[tuple[float, float, float]] = None,
        up: Optional[tuple[float, float, float]] = None,
        fov_deg: Optional[float] = None,
    ) -> Scene: ...
    @property
    def fingerprint(self) -> str: ...
    def __len__(self) -> int: ...

@final
class Interrupt:
    """Asks the runs given it to stop, from any thread: `run` then returns the best solution
    so far, marked partial."""

    def __init__(self) -> None: ...
    def set(self) -> None: ...
    def clear(self) -> None: ...
    @property
    def is_set(self) -> bool: ...

@final
class RunOutput:
    def arrays(self) -> dict[str, Any]: ...
    def report_json(self) -> str: ...
    def solution_json(self) -> str: ...
    def write(
        self, directory: str, svg: Union[str, list[str]], convergence: bool, export: str
    ) -> list[Path]: ...
    def interpolate(
        self, points: np.ndarray, surfaces: list[int], quantity: str
    ) -> np.ndarray: ...
    def render(self) -> np.ndarray: ...
    @property
    def scene(self) -> Scene: ...

def builtin_scenes() -> list[tuple[str, str]]: ...
def run(
    scene: Scene,
    arguments: dict[str, Any],
    threads: Optional[int] = None,
    interrupt: Optional[Interrupt] = None,
    progress: Optional[Callable[[str, int, int], object]] = None,
) -> tuple[Optional[RunOutput], Optional[BaseException]]: ...
def direct_light(
    scene: Scene,
    points: np.ndarray,
    normals: np.ndarray,
    surfaces: Optional[list[int]] = None,
    threads: Optional[int] = None,
) -> np.ndarray: ...
def discontinuities(
    scene: Scene,
    eee: bool = True,
    events: str = "complete",
    event_tol: Optional[float] = None,
    max_elements: Optional[int] = None,
    threads: Optional[int] = None,
) -> dict[str, Any]: ...
def reference(
    scene: Scene,
    points: np.ndarray,
    surfaces: Optional[list[int]] = None,
    paths: int = 4096,
    seed: int = 1,
    threads: Optional[int] = None,
) -> tuple[np.ndarray, np.ndarray]: ...
def locate(
    scene: Scene, points: np.ndarray, normals: Optional[np.ndarray] = None
) -> np.ndarray: ...
