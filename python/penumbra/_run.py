"""``penumbra.run``: the command line's ``penumbra run``, from Python."""

from __future__ import annotations

import sys
from typing import Callable, Literal, Optional, Union

from . import _checks, _native
from ._scene import Scene
from ._solution import Solution

Interrupt = _native.Interrupt

MeshMethod = Literal["auto", "uniform", "discontinuity"]
SolverMethod = Literal["hierarchical", "progressive", "jacobi", "gauss-seidel", "direct", "photon-map"]
FormFactors = Literal["analytic", "monte-carlo", "hemicube"]

_MESHES = ("auto", "uniform", "discontinuity")
_SOLVERS = ("hierarchical", "progressive", "jacobi", "gauss-seidel", "direct", "photon-map")
_FORM_FACTORS = ("analytic", "monte-carlo", "hemicube")


ProgressCallback = Callable[[str, int, int], object]


class _StderrProgress:
    """``progress=True``: one line on stderr per stage, its percentage updated in place."""

    def __call__(self, stage: str, done: int, total: int) -> None:
        percent = 100.0 * done / total if total else 100.0
        end = "\n" if done >= total else ""
        sys.stderr.write(f"\r{stage:>16} {percent:5.1f}%{end}")
        sys.stderr.flush()


class RunInterrupted(KeyboardInterrupt):
    """A run stopped by Ctrl-C. ``solution`` holds the best solution so far (marked
    ``partial``), or None when none existed yet."""

    def __init__(self, solution: Optional[Solution]) -> None:
        state = "with a partial solution" if solution is not None else "before a solution existed"
        super().__init__(f"the run was interrupted {state}")
        self.solution = solution


class RunCancelled(RuntimeError):
    """A run stopped by :meth:`Interrupt.set` before any solution existed (after that, ``run``
    returns the partial solution)."""


def run(
    scene: Scene,
    *,
    mesh: MeshMethod = "auto",
    max_elements: Optional[int] = None,
    tol: Optional[float] = None,
    min_angle: Optional[float] = None,
    penumbra_density: Optional[float] = None,
    eee: bool = True,
    events: Literal["complete", "extremal"] = "complete",
    event_tol: Optional[float] = None,
    refine_tol: Optional[float] = None,
    initial_elements: Optional[int] = None,
    refine_indirect: Literal["gradient", "gathered"] = "gradient",
    refine_rounds: Optional[int] = None,
    solver: SolverMethod = "hierarchical",
    link_tol: Optional[float] = None,
    photons: Optional[int] = None,
    gather_photons: Optional[int] = None,
    final_gather: Optional[int] = None,
    form_factors: FormFactors = "analytic",
    ff_samples: Optional[int] = None,
    hemicube_resolution: Optional[int] = None,
    epsilon: Optional[float] = None,
    max_shots: Optional[int] = None,
    direct_only: bool = False,
    rays: Optional[int] = None,
    elements_per_patch: Optional[int] = None,
    seed: Optional[int] = None,
    time_budget: Optional[float] = None,
    threads: Optional[int] = None,
    memory_limit: Optional[float] = None,
    width: Optional[int] = None,
    height: Optional[int] = None,
    interrupt: Optional[Interrupt] = None,
    progress: Union[bool, ProgressCallback, None] = None,
) -> Solution:
    """Meshes, lights and solves ``scene`` as ``penumbra run`` does, with the same options and
    defaults (``penumbra run --help``, ``docs/cli.md``); the same options give the same
    ``solution.json``, to the bit.

    The main options: ``mesh`` ``"auto"`` (error-driven: the lines that bound umbrae and
    penumbrae as mesh edges, refined where the exact direct light's measured interpolation
    error is largest, until each surface's RMS error is within ``tol`` of its mean or the
    budget is spent, and in full solutions again where the light reflected more than once
    bends), ``"uniform"`` or ``"discontinuity"``; ``min_angle`` the smallest angle
    (degrees) their quality refinement aims for (0: none); ``max_elements`` caps the triangles for the
    whole scene (default 25,000 with the hierarchical solver, 10,000 with the others and
    ``direct_only``, or what the scene needs if more); ``solver`` ``"hierarchical"``,
    ``"progressive"``, ``"jacobi"``, ``"gauss-seidel"``, ``"direct"`` or ``"photon-map"`` (with
    ``photons``, ``gather_photons`` and ``final_gather``); ``direct_only``
    solves one exact bounce; ``refine_tol`` turns on adaptive refinement from
    ``initial_elements`` up to ``max_elements``; ``time_budget`` (seconds) stops early with the
    best solution so far; ``threads`` workers (default one per core; results do not depend on
    it); ``seed`` seeds the visibility sampling; ``width`` and ``height`` size the render.
    ``None`` means the command line's default.

    ``progress=True`` shows each stage's progress on stderr; a callable gets
    ``progress(stage, done, total)`` from the worker threads as a stage starts, a few times a
    second while it runs, and as it ends (``done == total``); it may feed a tqdm bar. An
    exception it raises stops the reports and is raised when the run ends.

    The GIL is released while the run computes. Ctrl-C stops it and raises
    :class:`RunInterrupted` carrying the partial solution (a second Ctrl-C raises at once,
    leaving the run to end in the background); an exception from another signal handler is
    raised as it is, with the partial solution as its ``solution`` attribute; ``interrupt.set()`` from another
    thread stops it and ``run`` returns the partial solution (``solution.partial``; the scene's
    least mesh with its direct light if no mesh had values yet, ``solution.report["stopped"]``
    says where it stopped); ``interrupt.clear()`` lets it start runs again.

    Raises ``ValueError`` for an option out of range (naming it), ``TypeError`` for a value of
    the wrong kind, ``MemoryError`` when the run would not fit in memory (saying what would)."""
    if not isinstance(scene, Scene):
        raise TypeError(f"scene must be a penumbra.Scene, not {type(scene).__name__}")
    if interrupt is not None and not isinstance(interrupt, Interrupt):
        raise TypeError(f"interrupt must be a penumbra.Interrupt, not {type(interrupt).__name__}")
    arguments = {
        "mesh": _checks.choice(mesh, "mesh", _MESHES),
        "max_elements": _checks.count(max_elements, "max_elements"),
        "tol": _checks.number(tol, "tol"),
        "min_angle": _checks.number(min_angle, "min_angle"),
        "penumbra_density": _checks.number(penumbra_density, "penumbra_density"),
        "eee": _checks.flag(eee, "eee"),
        "events": _checks.choice(events, "events", ("complete", "extremal")),
        "event_tol": _checks.number(event_tol, "event_tol"),
        "refine_tol": _checks.number(refine_tol, "refine_tol"),
        "initial_elements": _checks.count(initial_elements, "initial_elements"),
        "refine_indirect": _checks.choice(refine_indirect, "refine_indirect", ("gradient", "gathered")),
        "refine_rounds": _checks.count(refine_rounds, "refine_rounds"),
        "solver": _checks.choice(solver, "solver", _SOLVERS),
        "link_tol": _checks.number(link_tol, "link_tol"),
        "photons": _checks.count(photons, "photons"),
        "gather_photons": _checks.count(gather_photons, "gather_photons"),
        "final_gather": _checks.count(final_gather, "final_gather", minimum=0),
        "form_factors": _checks.choice(form_factors, "form_factors", _FORM_FACTORS),
        "ff_samples": _checks.count(ff_samples, "ff_samples"),
        "hemicube_resolution": _checks.count(hemicube_resolution, "hemicube_resolution"),
        "epsilon": _checks.number(epsilon, "epsilon"),
        "max_shots": _checks.count(max_shots, "max_shots", minimum=0),
        "direct_only": _checks.flag(direct_only, "direct_only"),
        "rays": _checks.count(rays, "rays"),
        "elements_per_patch": _checks.count(elements_per_patch, "elements_per_patch"),
        "seed": _checks.count(seed, "seed", minimum=0),
        "time_budget": _checks.number(time_budget, "time_budget", positive=True),
        "memory_limit": _checks.number(memory_limit, "memory_limit", positive=True),
        "width": _checks.count(width, "width", maximum=2**32 - 1),
        "height": _checks.count(height, "height", maximum=2**32 - 1),
    }
    if progress is True:
        progress = _StderrProgress()
    elif progress is False:
        progress = None
    if progress is not None and not callable(progress):
        raise TypeError(f"progress must be True, False, None or a callable, not {type(progress).__name__}")
    output, signal = _native.run(
        scene._native, arguments, _checks.count(threads, "threads"), interrupt, progress
    )
    solution = Solution(output) if output is not None else None
    if isinstance(signal, KeyboardInterrupt):
        raise RunInterrupted(solution) from signal
    if signal is not None:
        # Another signal handler's exception (a SIGALRM timeout, SystemExit on SIGTERM), as it
        # was raised, with the best solution so far when it can carry one.
        try:
            setattr(signal, "solution", solution)
        except (AttributeError, TypeError):
            pass
        raise signal
    if solution is None:
        raise RunCancelled("the run was interrupted before a solution existed")
    return solution
