"""The examples in the package's docstrings run and print what they say."""

from __future__ import annotations

import doctest

import numpy as np
import pytest

import penumbra
from penumbra import _research, _scene, _solution


@pytest.mark.parametrize("module", [penumbra, _scene, _research, _solution], ids=lambda m: m.__name__)
def test_docstring_examples_hold(module):
    failures, attempted = doctest.testmod(module, optionflags=doctest.ELLIPSIS)
    assert attempted > 0, f"{module.__name__} has no examples"
    assert failures == 0


def test_interpolation_at_the_vertices_gives_their_values():
    solution = penumbra.run(penumbra.Scene.builtin("cornell"), max_elements=3000)
    # Contact lines have a vertex per side at one position, each with its own side's light:
    # interpolation there takes one side's. Every other vertex is alone where it is.
    keys = np.column_stack([solution.surface_id, solution.vertices])
    _, first, counts = np.unique(keys, axis=0, return_index=True, return_counts=True)
    alone = np.sort(first[counts == 1])
    assert len(alone) > 0.8 * len(solution.vertices)
    ids = solution.surface_id[alone].astype(int)
    for quantity in ("radiosity", "direct", "indirect", "irradiance", "direct_irradiance"):
        got = solution.interpolate(solution.vertices[alone], surfaces=ids, quantity=quantity)
        expected = getattr(solution, quantity)[alone]
        assert np.allclose(got, expected, rtol=0, atol=1e-12 * np.abs(expected).max()), quantity
    # Between the vertices: the mean of a triangle's corners at its centroid.
    triangles = solution.triangles[:50]
    centroids = solution.vertices[triangles].mean(axis=1)
    got = solution.interpolate(centroids, surfaces=solution.triangle_surface_id[:50].astype(int))
    assert np.allclose(got, solution.radiosity[triangles].mean(axis=1), rtol=1e-9, atol=1e-12)
    assert np.isnan(solution.interpolate([[0, -1e4, 0]])).all()  # on no surface
    floor = solution.scene.surface_id("floor")
    off = solution.interpolate([[1000, 0, 100]], surfaces=[floor])  # in the floor's plane, beyond it
    assert np.isnan(off).all()


def test_surface_coordinates_follow_the_frame():
    solution = penumbra.run(penumbra.Scene.builtin("cornell"), max_elements=3000)
    floor = solution["floor"]
    frame = solution.scene.frame("floor")
    back = frame["origin"] + floor.uv[:, :1] * frame["u"] + floor.uv[:, 1:] * frame["v"]
    assert np.allclose(back, floor.vertices, atol=1e-9 * 560)
    # The lights' own direct irradiance is kept where their reflectance makes `direct` zero.
    light = solution["light"]
    assert not light.direct.any() and not light.direct_irradiance.any()  # it faces away from itself
    lit = solution["floor"]
    assert np.allclose(lit.direct, solution.scene.reflectance[lit.index] * lit.direct_irradiance)
