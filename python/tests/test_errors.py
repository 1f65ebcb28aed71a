"""Bad arguments raise ValueError or TypeError naming the argument, and nothing a caller passes
crashes the interpreter."""

from __future__ import annotations

import subprocess
import sys
import textwrap

import numpy as np
import pytest

import penumbra

TEXTBOOK = penumbra.Scene.builtin("textbook")

# (call, exception, a word the message must hold)
BAD_RUNS = [
    (dict(max_elements=-5), ValueError, "max_elements"),
    (dict(max_elements=0), ValueError, "max_elements"),
    (dict(max_elements=2.5), TypeError, "max_elements"),
    (dict(max_elements="many"), TypeError, "max_elements"),
    (dict(max_elements=True), TypeError, "max_elements"),
    (dict(time_budget=float("nan")), ValueError, "time_budget"),
    (dict(time_budget=-1.0), ValueError, "time_budget"),
    (dict(refine_tol=float("inf")), ValueError, "refine_tol"),
    (dict(refine_tol=2.0), ValueError, "refine_tol"),
    (dict(penumbra_density=0.5), ValueError, "penumbra_density"),
    (dict(solver="multigrid"), ValueError, "solver"),
    (dict(solver=3), TypeError, "solver"),
    (dict(mesh="adaptive"), ValueError, "mesh"),
    (dict(rays=10**12), ValueError, "rays"),
    (dict(threads=0), ValueError, "threads"),
    (dict(threads=10**6), ValueError, "threads"),
    (dict(seed=-1), ValueError, "seed"),
    (dict(seed=2**70), ValueError, "seed must be at most"),
    (dict(width=100000), ValueError, "width"),
    (dict(memory_limit=0), ValueError, "memory_limit"),
    (dict(direct_only="yes"), TypeError, "direct_only"),
    (dict(max_elements=3), ValueError, "max_elements"),  # below the scene's least mesh
    (dict(solver="jacobi", refine_tol=0.01), ValueError, "solver"),
    (dict(epsilon=0.0), ValueError, "epsilon"),
    (dict(solver="photon-map", photons=0), ValueError, "photons"),
    (dict(solver="photon-map", gather_photons=0), ValueError, "gather_photons"),
    (dict(solver="photon-map", final_gather=-1), ValueError, "final_gather"),
]


@pytest.mark.parametrize("options,exception,word", BAD_RUNS, ids=[str(o) for o, _, _ in BAD_RUNS])
def test_bad_run_options_name_their_argument(options, exception, word):
    with pytest.raises(exception, match=word):
        penumbra.run(TEXTBOOK, **options)


def test_a_run_that_would_not_fit_says_what_would():
    with pytest.raises(MemoryError, match="max_elements"):
        penumbra.run(TEXTBOOK, max_elements=400000, memory_limit=1.0)


BAD_POINTS = [
    (dict(points=[[0, 0]]), ValueError, "points must have shape"),
    (dict(points=[[0, 0, float("nan")]]), ValueError, "points: row 0 is not finite"),
    (dict(points=[["a", "b", "c"]]), TypeError, "points must hold real numbers"),
    (dict(points=[[1, 2, 3], [4, 5]]), TypeError, "points"),
    (dict(points=np.zeros((2, 3), dtype=complex)), TypeError, "points"),
    (dict(normals=[[0, 0, 1], [0, 0, 1]]), ValueError, "normals has 2 rows for 1 points"),
    (dict(normals=[0, 0, 0]), ValueError, "normals"),
    (dict(surfaces=[7]), ValueError, "surfaces"),
    (dict(surfaces=[0.5]), TypeError, "surfaces"),
    (dict(surfaces=[0, 1]), ValueError, "surfaces"),
    (dict(threads=-2), ValueError, "threads"),
]


@pytest.mark.parametrize("change,exception,words", BAD_POINTS, ids=[str(c) for c, _, _ in BAD_POINTS])
def test_bad_points_name_their_argument(change, exception, words):
    arguments = dict(points=[[0, 0, 0]], normals=[0, 0, 1])
    arguments.update(change)
    with pytest.raises(exception, match=words):
        penumbra.direct_light(TEXTBOOK, arguments.pop("points"), arguments.pop("normals"), **arguments)


def test_other_bad_arguments_name_themselves():
    with pytest.raises(TypeError, match="scene must be a penumbra.Scene"):
        penumbra.run("cornell")
    with pytest.raises(ValueError, match="paths must be at least 1"):
        penumbra.reference(TEXTBOOK, [[0, 0, 0]], paths=0)
    with pytest.raises(ValueError, match="paths"):
        penumbra.reference(TEXTBOOK, [[0, 0, 0]], paths=10**12)
    with pytest.raises(ValueError, match="events"):
        penumbra.discontinuities(TEXTBOOK, events="all")
    assert len(penumbra.discontinuities(TEXTBOOK, events=None)) == len(penumbra.discontinuities(TEXTBOOK))
    floor = TEXTBOOK.surface_id("floor")
    with pytest.raises(ValueError, match="point 0 .* does not lie on surface"):
        penumbra.reference(TEXTBOOK, [[0.8, 0.1, -50]], surfaces=[floor])
    with pytest.raises(ValueError, match="point 0 has no surface"):
        penumbra.reference(TEXTBOOK, [[0.8, 0.1, 0]], surfaces=[-1])
    with pytest.raises(ValueError, match="no surface id"):
        penumbra.direct_light(TEXTBOOK, [[0, 0, 0]], [0, 0, 1], surfaces=np.array([2**63], np.uint64))
    with pytest.raises(TypeError, match="svg"):
        penumbra.run(TEXTBOOK, direct_only=True, max_elements=500).write("unused", svg=5)
    with pytest.raises(ValueError, match="width/height"):
        penumbra.run(TEXTBOOK, width=16384, height=16384)  # each side allowed, not the whole
    # Normals of any length that has a direction.
    tiny = penumbra.direct_light(TEXTBOOK, [[2, 2, 0]], [0, 0, 1e-300])
    assert np.array_equal(tiny, penumbra.direct_light(TEXTBOOK, [[2, 2, 0]], [0, 0, 1e300]))
    assert tiny.max() > 0
    with pytest.raises(ValueError, match="reflectance has 1 rows for 2 polygons"):
        penumbra.Scene.from_polygons([[[0, 0, 0], [1, 0, 0], [0, 1, 0]]] * 2, reflectance=[[0.5] * 3])
    with pytest.raises(ValueError, match=r"polygons\[1\] must have shape"):
        penumbra.Scene.from_polygons([[[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 0]]], reflectance=[0.5] * 3)
    with pytest.raises(TypeError, match="make a Scene with"):
        penumbra.Scene(object())
    with pytest.raises(ValueError, match="svg"):
        penumbra.run(TEXTBOOK, direct_only=True, max_elements=500).write("/nonexistent-dir", svg="some")


FUZZ = textwrap.dedent(
    """
    import random, numpy as np, penumbra
    rng = random.Random(5)
    values = [None, 0, -1, 1, 2**70, -2**70, 1.5, float("nan"), float("inf"), "", "x", b"x", [], [[]],
              [1, 2, 3], [[1, 2, 3]], np.zeros((0, 3)), np.ones((2, 3)), np.full((1, 3), np.nan),
              np.zeros((3, 3), dtype=np.int8), object(), {}, {"eye": 1}, True, (1, 2, 3)]
    scene = penumbra.Scene.builtin("textbook")
    calls = [
        lambda v: penumbra.run(scene, **{rng.choice(["max_elements", "solver", "seed", "rays", "time_budget",
            "refine_tol", "threads", "width", "link_tol", "event_tol", "interrupt", "mesh"]): v},
            direct_only=True),
        lambda v: penumbra.direct_light(scene, v, [0, 0, 1]),
        lambda v: penumbra.direct_light(scene, [[0, 0, 0]], v),
        lambda v: penumbra.direct_light(scene, [[0, 0, 0]], [0, 0, 1], surfaces=v),
        lambda v: penumbra.reference(scene, v, paths=16),
        lambda v: penumbra.discontinuities(scene, max_elements=v),
        lambda v: penumbra.Scene.from_polygons(v, reflectance=[0.5] * 3),
        lambda v: penumbra.Scene.from_polygons([[[0, 0, 0], [1, 0, 0], [0, 1, 0]]], reflectance=v),
        lambda v: penumbra.Scene.from_polygons([[[0, 0, 0], [1, 0, 0], [0, 1, 0]]], reflectance=[0.5] * 3, camera=v),
        lambda v: penumbra.Scene.load(v),
        lambda v: penumbra.Scene.from_json(v),
        lambda v: scene.locate(v),
    ]
    outcomes = {}
    for call in calls:
        for v in values:
            try:
                call(v)
                outcome = "ok"
            except (ValueError, TypeError, FileNotFoundError, KeyboardInterrupt) as e:
                outcome = type(e).__name__
            outcomes[outcome] = outcomes.get(outcome, 0) + 1
    print(outcomes)
    """
)


def test_no_argument_crashes_the_interpreter():
    # In a process of its own: a crash would end it with a signal, not an exception.
    done = subprocess.run([sys.executable, "-c", FUZZ], capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr
    assert "ValueError" in done.stdout and "TypeError" in done.stdout, done.stdout
