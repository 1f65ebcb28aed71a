"""The research primitives against independent truth: direct_light against the closed forms of
the analytic notes (docs/closed-forms.md), discontinuities against the run's mesh, and
reference against the furnace's B = E / (1 - rho)."""

from __future__ import annotations

import numpy as np
import pytest

import penumbra

M = 3.0  # exitance of the lights below, W/m²
FLOOR = [[-5, -5, 0], [5, -5, 0], [5, 5, 0], [-5, 5, 0]]


def lit(light, floor=FLOOR):
    """A light polygon over (or beside) a grey floor through the origin."""
    return penumbra.Scene.from_polygons(
        [light, floor], names=["light", "floor"], reflectance=[[0] * 3, [0.5] * 3],
        emission=[[M] * 3, [0] * 3],
    )


def facing_down(corners):
    """Corners in the order that makes the polygon face -z (towards the origin)."""
    return corners[::-1]


# (light polygon, form factor from the origin with normal +z): analytic notes 1.1, 1.2, 1.6.
CASES = {
    "parallel rectangle 1 x 1 at 1 (1.1)": (
        facing_down([[0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]]), 0.138531605994893),
    "parallel rectangle 2 x 3 at 1 (1.1)": (
        facing_down([[0, 0, 1], [2, 0, 1], [2, 3, 1], [0, 3, 1]]), 0.217575206107758),
    "parallel rectangle 0.5 x 0.25 at 2 (1.1)": (
        facing_down([[0, 0, 2], [0.5, 0, 2], [0.5, 0.25, 2], [0, 0.25, 2]]), 0.00945845765854797),
    "perpendicular rectangle a 2, b 1, c 0.5 (1.2)": (
        [[0.5, 0, 0], [0.5, 0, 2], [0.5, 1, 2], [0.5, 1, 0]], 0.158774804514299),
    "perpendicular rectangle a 1, b 3, c 2 (1.2)": (
        [[2, 0, 0], [2, 0, 1], [2, 3, 1], [2, 3, 0]], 0.0239896394221535),
    "triangle at 1 (1.6 A)": (facing_down([[0, 0, 1], [1, 0, 1], [0, 1, 1]]), 0.0962250448649376),
}


@pytest.mark.parametrize("case", sorted(CASES))
def test_direct_light_equals_the_closed_forms(case):
    light, form_factor = CASES[case]
    # The floor must not reach under a wall-like light standing on it.
    floor = FLOOR if min(p[2] for p in light) > 0 else [[-5, -5, 0], [0.4, -5, 0], [0.4, 5, 0], [-5, 5, 0]]
    h = penumbra.direct_light(lit(light, floor), [[0, 0, 0]], [0, 0, 1])
    assert h.shape == (1, 3) and h.dtype == np.float64
    assert np.allclose(h, M * form_factor, rtol=1e-12, atol=0), (h, M * form_factor)


def test_a_light_half_below_the_horizon_counts_its_upper_half():
    # Analytic notes 1.6 D: clipping at the tangent plane; Lambert's formula unclipped gives 0.
    square = [[1, -1, -1], [1, -1, 1], [1, 1, 1], [1, 1, -1]]
    scene = penumbra.Scene.from_polygons(
        [square, [[-3, -1, -3], [-3, 1, -3], [-3, 1, 3], [-3, -1, 3]]],
        names=["light", "wall"], reflectance=[[0] * 3, [0.5] * 3], emission=[[M] * 3, [0] * 3],
    )
    h = penumbra.direct_light(scene, [[0, 0, 0]], [0, 0, 1], surfaces=[-1])
    assert np.allclose(h, M * 0.111468394005107, rtol=1e-12, atol=0)


def test_superposition_gives_any_parallel_rectangle():
    # The floor's point (0.25, 0.5) under the 1 x 1 light: four corner rectangles of 1.1.
    def corner(a, b, c=1.0):
        x, y = a / c, b / c
        return (x / np.hypot(1, x) * np.arctan(y / np.hypot(1, x))
                + y / np.hypot(1, y) * np.arctan(x / np.hypot(1, y))) / (2 * np.pi)

    light = facing_down([[0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]])
    expected = corner(0.25, 0.5) + corner(0.75, 0.5) + corner(0.25, 0.5) + corner(0.75, 0.5)
    h = penumbra.direct_light(lit(light), [[0.25, 0.5, 0]], [[0, 0, 1]])
    assert np.allclose(h, M * expected, rtol=1e-12, atol=0)


def test_direct_light_is_zero_in_the_umbra_and_matches_the_runs_vertices():
    scene = penumbra.Scene.builtin("textbook")
    floor = scene.surface_id("floor")
    assert not penumbra.direct_light(scene, [[0, 0, 0], [0.3, -0.2, 0]], [0, 0, 1]).any()
    solution = penumbra.run(scene, direct_only=True, max_elements=2000)
    on = solution.surface_id == floor
    rho = scene.reflectance[floor]
    h = penumbra.direct_light(scene, solution.vertices[on], [0, 0, 1])
    assert np.allclose(rho * h, solution.direct[on], rtol=1e-9, atol=1e-12)


def test_discontinuities_without_a_mesh_are_the_runs_segments():
    scene = penumbra.Scene.builtin("textbook")
    found = penumbra.discontinuities(scene, max_elements=2000)
    solution = penumbra.run(scene, direct_only=True, max_elements=2000, mesh="discontinuity")
    assert len(found) > 0 and found.stats["segments"] == len(found)
    assert np.array_equal(found.segments, solution.discontinuities.segments)
    assert np.array_equal(found.event, solution.discontinuities.event)
    assert np.array_equal(found.order, solution.discontinuities.order)
    # The square blocker over the floor: its umbra and penumbra outlines, each a square.
    on_floor = found.where(found.surface_id == scene.surface_id("floor"))
    assert set(on_floor.boundary) >= {"umbra", "penumbra"}
    fewer = penumbra.discontinuities(scene, events="extremal", eee=False)
    assert 0 < len(fewer) <= len(found)


def test_reference_finds_the_furnaces_radiosity():
    scene = penumbra.Scene.builtin("furnace")  # closed cube, E = 1, rho = 0.5: B = 2 everywhere
    points = [[0.5, 0.5, 0.0], [0.1, 0.9, 0.0], [0.5, 0.0, 0.5]]
    ids = scene.locate(points)
    assert (ids >= 0).all()
    radiosity, error = penumbra.reference(scene, points, paths=1024, seed=3)
    assert radiosity.shape == (3, 3) and error.shape == (3,)
    assert (np.abs(radiosity.mean(axis=1) - 2.0) < 4 * error + 1e-12).all(), (radiosity, error)
    again, _ = penumbra.reference(scene, points, surfaces=ids, paths=1024, seed=3, threads=1)
    assert np.array_equal(again, radiosity)
    with pytest.raises(ValueError, match="point 0 .* lies on no surface"):
        penumbra.reference(scene, [[0.5, 0.5, 0.5]])
