"""`penumbra.run` against the command line and against conservation: the same options give the
same solution to the bit, and the arrays keep their promises."""

from __future__ import annotations

import json
import threading
import time

import numpy as np
import pytest

import penumbra
from conftest import run_cli, solution_arrays

# (scene, command-line flags, the same options for Python)
SAME_RUNS = [
    ("textbook", ["--direct-only", "--mesh", "uniform", "--max-elements", "2000"],
     dict(direct_only=True, mesh="uniform", max_elements=2000)),
    ("cornell", ["--solver", "progressive", "--max-elements", "3000", "--seed", "7"],
     dict(solver="progressive", max_elements=3000, seed=7)),
    ("cornell", ["--max-elements", "4000"], dict(max_elements=4000)),
    ("cornell", ["--solver", "progressive", "--refine-tol", "0.01", "--max-elements", "4000"],
     dict(solver="progressive", refine_tol=0.01, max_elements=4000)),
    ("bars", ["--solver", "gauss-seidel", "--max-elements", "2500", "--events", "extremal"],
     dict(solver="gauss-seidel", max_elements=2500, events="extremal")),
    ("cornell", ["--solver", "photon-map", "--max-elements", "2000", "--photons", "50000",
                 "--gather-photons", "40", "--final-gather", "64"],
     dict(solver="photon-map", max_elements=2000, photons=50000, gather_photons=40, final_gather=64)),
]


@pytest.mark.parametrize("scene,flags,options", SAME_RUNS, ids=[f"{s}-{i}" for i, (s, _, _) in enumerate(SAME_RUNS)])
def test_arrays_equal_the_command_lines_solution_to_the_bit(cli, tmp_path, scene, flags, options):
    run_cli(cli, "run", scene, "--out", "out", "--quiet", "--svg", "none", *flags, cwd=tmp_path)
    expected = solution_arrays(tmp_path / "out" / "solution.json")
    solution = penumbra.run(penumbra.Scene.builtin(scene), **options)

    for name in ("vertices", "triangles", "radiosity"):
        got = getattr(solution, name)
        assert got.dtype == expected[name].dtype and got.shape == expected[name].shape, name
        assert np.array_equal(got, expected[name]), f"{name} differs from solution.json"
    assert np.array_equal(solution.discontinuities.segments, expected["segments"])
    assert np.array_equal(solution.discontinuities.event, expected["event"])
    assert np.array_equal(solution.discontinuities.order, expected["order"])
    assert solution.solution_json() == (tmp_path / "out" / "solution.json").read_text()


def test_written_files_are_the_command_lines(cli, tmp_path):
    run_cli(cli, "run", "textbook", "--direct-only", "--max-elements", "1500", "--out", "cli", "--quiet", cwd=tmp_path)
    solution = penumbra.run(penumbra.Scene.builtin("textbook"), direct_only=True, max_elements=1500)
    written = solution.write(tmp_path / "py")
    names = sorted(p.relative_to(tmp_path / "py").as_posix() for p in written)
    expected = sorted(p.relative_to(tmp_path / "cli").as_posix() for p in (tmp_path / "cli").rglob("*") if p.is_file())
    assert names == expected
    assert (tmp_path / "py" / "solution.json").read_bytes() == (tmp_path / "cli" / "solution.json").read_bytes()
    assert (tmp_path / "py" / "render.png").read_bytes() == (tmp_path / "cli" / "render.png").read_bytes()
    report = json.loads((tmp_path / "py" / "report.json").read_text())
    assert report == solution.report
    assert report["counts"]["triangles"] == solution.triangle_count == len(solution.triangles)
    assert "invocation" not in report  # no command line asked for it


def test_exports_are_the_command_lines(cli, tmp_path):
    options = ["--direct-only", "--max-elements", "1500", "--quiet"]
    run_cli(cli, "run", "textbook", *options, "--export", "all", "--out", "cli", cwd=tmp_path)
    solution = penumbra.run(penumbra.Scene.builtin("textbook"), direct_only=True, max_elements=1500)
    written = {p.name for p in solution.write(tmp_path / "py", export=["vtp", "ply", "glb", "obj", "html"])}
    exports = ["solution.vtp", "solution.ply", "solution.glb", "solution.obj", "solution.mtl"]
    assert written >= {*exports, "index.html"}
    for name in exports:
        assert (tmp_path / "py" / name).read_bytes() == (tmp_path / "cli" / name).read_bytes(), name
    # index.html is not compared: it embeds report.json, whose command line only the CLI records.
    assert "index.html" not in {p.name for p in solution.write(tmp_path / "none", export="none")}
    assert not (tmp_path / "none" / "index.html").exists()
    with pytest.raises(ValueError, match="export: \"stl\" is not a format"):
        solution.write(tmp_path / "bad", export="vtp,stl")
    assert not (tmp_path / "bad").exists()


def test_light_splits_into_emission_direct_and_indirect():
    scene = penumbra.Scene.builtin("cornell")
    solution = penumbra.run(scene, max_elements=3000)
    emission = scene.emission[solution.surface_id]
    rho = scene.reflectance[solution.surface_id]
    total = emission + solution.direct + solution.indirect
    assert np.allclose(solution.radiosity, total, rtol=1e-12, atol=1e-12 * solution.radiosity.max())
    assert np.allclose(solution.radiosity, emission + rho * solution.irradiance, rtol=1e-12, atol=0)
    # Light reflected more than once is never negative. The light faces down: the ceiling gets
    # no direct light, only what the room reflects.
    assert (solution.indirect >= 0).all()
    ceiling = solution.surface_id == scene.surface_id("ceiling")
    assert not solution.direct[ceiling].any()
    assert solution.indirect[ceiling].mean() > 0


def test_direct_only_has_no_indirect_light():
    scene = penumbra.Scene.builtin("textbook")
    solution = penumbra.run(scene, direct_only=True, max_elements=1500)
    assert not solution.indirect.any()
    rho = scene.reflectance[solution.surface_id]
    assert np.array_equal(solution.direct, rho * solution.irradiance)
    assert np.array_equal(solution.radiosity, scene.emission[solution.surface_id] + solution.direct)


def test_per_surface_views_match_the_whole():
    solution = penumbra.run(penumbra.Scene.builtin("cornell"), max_elements=3000)
    assert [s.name for s in solution.surfaces] == solution.scene.surface_names
    assert sum(len(s.vertices) for s in solution.surfaces) == len(solution.vertices)
    assert sum(len(s.discontinuities) for s in solution.surfaces) == len(solution.discontinuities)
    for surface in solution.surfaces:
        assert (solution.surface_id[: len(solution.vertices)] == surface.index).sum() == len(surface.vertices)
        if len(surface.triangles):
            assert surface.triangles.max() < len(surface.vertices)
        assert (surface.discontinuities.surface_id == surface.index).all()
    floor = solution["floor"]
    assert floor is solution[solution.scene.surface_id("floor")]
    assert np.array_equal(floor.radiosity, solution.radiosity[solution.surface_id == floor.index])
    with pytest.raises(KeyError, match="no surface named 'ceiling-fan'"):
        solution["ceiling-fan"]


def test_results_do_not_depend_on_threads():
    scene = penumbra.Scene.builtin("cornell")
    one = penumbra.run(scene, max_elements=3000, threads=1)
    two = penumbra.run(scene, max_elements=3000, threads=2)
    assert one.solution_json() == two.solution_json()


def test_the_gil_is_released_while_a_run_computes():
    counted = []
    done = threading.Event()

    def count():
        while not done.is_set():
            counted.append(1)
            time.sleep(0.001)

    counter = threading.Thread(target=count)
    counter.start()
    started = time.perf_counter()
    penumbra.run(penumbra.Scene.builtin("cornell"), max_elements=8000)
    seconds = time.perf_counter() - started
    done.set()
    counter.join()
    # Sleeping 1 ms a turn, a free thread counts several hundred times a second.
    assert len(counted) > 100 * seconds, (len(counted), seconds)


def test_a_time_budget_gives_a_partial_solution():
    solution = penumbra.run(penumbra.Scene.builtin("cornell"), solver="progressive", max_elements=8000,
                            epsilon=1e-12, time_budget=1.0)
    assert solution.partial
    assert np.isfinite(solution.radiosity).all() and (solution.radiosity >= 0).all()


def test_progress_reports_each_stage_from_start_to_end():
    reports = []
    penumbra.run(penumbra.Scene.builtin("cornell"), max_elements=4000,
                 progress=lambda stage, done, total: reports.append((stage, done, total)))
    stages = [r[0] for r in reports]
    assert {"discontinuities", "meshing", "direct light"} <= set(stages)
    # Each stage: a report at 0 first, its steps never going back, and one at its total last.
    runs, current = [], []
    for report in reports:
        if report[1] == 0 and current and current[-1][1] == current[-1][2]:
            runs.append(current)
            current = []
        current.append(report)
    runs.append(current)
    for stage in runs:
        assert stage[0][1] == 0 and stage[-1][1] == stage[-1][2], stage
        assert len({name for name, _, _ in stage}) == 1, stage
        assert [d for _, d, _ in stage] == sorted(d for _, d, _ in stage), stage


def test_an_exception_in_the_progress_callback_is_raised():
    def failing(stage, done, total):
        raise ZeroDivisionError(f"in {stage}")

    with pytest.raises(ZeroDivisionError, match="in discontinuities"):
        penumbra.run(penumbra.Scene.builtin("cornell"), max_elements=2000, progress=failing)
    with pytest.raises(TypeError, match="progress"):
        penumbra.run(penumbra.Scene.builtin("cornell"), progress="yes")
