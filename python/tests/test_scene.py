"""Scenes from files, built-in names, arrays and JSON, and SceneError carrying every problem as
`penumbra check` reports them."""

from __future__ import annotations

import subprocess

import numpy as np
import pytest

import penumbra
from conftest import run_cli

LIGHT = [[-0.5, -0.5, 2], [-0.5, 0.5, 2], [0.5, 0.5, 2], [0.5, -0.5, 2]]
FLOOR = [[-2, -2, 0], [2, -2, 0], [2, 2, 0], [-2, 2, 0]]


def two_surfaces(**changes):
    arguments = dict(
        names=["light", "floor"],
        reflectance=[[0, 0, 0], [0.7, 0.6, 0.5]],
        emission=[[10, 10, 10], [0, 0, 0]],
    )
    arguments.update(changes)
    polygons = arguments.pop("polygons", [LIGHT, FLOOR])
    return penumbra.Scene.from_polygons(polygons, **arguments)


def test_builtin_scenes_are_the_command_lines(cli, tmp_path):
    names = penumbra.builtin_scenes()
    assert {"cornell", "textbook", "furnace"} <= set(names)
    for name in ("cornell", "textbook", "cie-5.8"):
        dumped = run_cli(cli, "scenes", "--dump", name, cwd=tmp_path).stdout
        assert penumbra.Scene.builtin(name).to_json() == dumped


def test_from_polygons_reads_back_through_json():
    scene = two_surfaces(camera={"eye": [0, -4, 1.8], "target": [0, 0, 0.7]})
    assert len(scene) == 2 and scene.surface_names == ["light", "floor"]
    assert np.array_equal(scene.polygons[1], np.array(FLOOR, dtype=float))
    assert np.array_equal(scene.reflectance, [[0, 0, 0], [0.7, 0.6, 0.5]])
    assert np.array_equal(scene.emission, [[10, 10, 10], [0, 0, 0]])
    assert np.allclose(scene.normals, [[0, 0, -1], [0, 0, 1]])
    assert np.allclose(scene.areas, [1, 16])
    assert scene.camera == {"eye": [0, -4, 1.8], "target": [0, 0, 0.7], "up": [0, 0, 1], "fov_deg": 45.0}
    again = penumbra.Scene.from_json(scene.to_json())
    assert again == scene and again.fingerprint == scene.fingerprint


def test_numpy_arrays_and_lists_make_the_same_scene():
    arrays = penumbra.Scene.from_polygons(
        np.array([LIGHT, FLOOR], dtype=np.float32),
        names=["light", "floor"],
        reflectance=np.array([[0, 0, 0], [0.7, 0.6, 0.5]]),
        emission=np.array([[10, 10, 10], [0, 0, 0]], dtype=np.int64),
    )
    assert arrays == two_surfaces()


def test_files_load_as_the_command_line_loads_them(cli, tmp_path):
    (tmp_path / "room.json").write_text(two_surfaces().to_json())
    loaded = penumbra.Scene.load(tmp_path / "room.json")
    assert loaded == two_surfaces() and loaded.source.endswith("room.json")
    (tmp_path / "lamp.obj").write_text(
        "mtllib lamp.mtl\n"
        "v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\n"
        "v -0.2 -0.2 1\nv -0.2 0.2 1\nv 0.2 0.2 1\nv 0.2 -0.2 1\n"
        "usemtl grey\nf 1 2 3\nf 1 3 4\nusemtl lamp\nf 5 6 7 8\n"
    )
    (tmp_path / "lamp.mtl").write_text("newmtl grey\nKd 0.5 0.5 0.5\nnewmtl lamp\nKd 0 0 0\nKe 5 5 5\n")
    merged = penumbra.Scene.load(str(tmp_path / "lamp.obj"))
    assert len(merged) == 2  # the floor's two triangles merge into one square
    assert len(penumbra.Scene.load(tmp_path / "lamp.obj", merge=False)) == 3
    run_cli(cli, "run", "lamp.obj", "--direct-only", "--out", "out", "--quiet", cwd=tmp_path)
    assert penumbra.run(merged, direct_only=True).solution_json() == (tmp_path / "out" / "solution.json").read_text()


def test_gltf_files_load_as_the_command_line_loads_them(cli, tmp_path):
    # The same lamp over a floor as a .gltf: two triangles of the floor, one quad of the lamp
    # drawn as a fan, each its node's; the buffer inline.
    import base64
    import json
    import struct

    floor = [[-1, 0, 1], [1, 0, 1], [1, 0, -1], [-1, 0, -1]]
    lamp = [[-0.2, 1, -0.2], [0.2, 1, -0.2], [0.2, 1, 0.2], [-0.2, 1, 0.2]]
    data = b"".join(struct.pack("<3f", *p) for p in floor + lamp) + struct.pack("<6H", 0, 1, 2, 0, 2, 3)
    accessor = lambda offset, count, kind, component: {
        "bufferView": 0, "byteOffset": offset, "count": count, "type": kind, "componentType": component}
    document = {
        "asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0, 1]}],
        "nodes": [{"name": "floor", "mesh": 0}, {"name": "lamp", "mesh": 1}],
        "meshes": [
            {"primitives": [{"attributes": {"POSITION": 0}, "indices": 2, "material": 0}]},
            {"primitives": [{"attributes": {"POSITION": 1}, "material": 1, "mode": 6}]},
        ],
        "materials": [{"name": "grey", "pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.5, 0.5, 1]}},
                      {"name": "glow", "emissiveFactor": [1, 1, 1]}],
        "accessors": [accessor(0, 4, "VEC3", 5126), accessor(48, 4, "VEC3", 5126), accessor(96, 6, "SCALAR", 5123)],
        "bufferViews": [{"buffer": 0, "byteLength": len(data)}],
        "buffers": [{"byteLength": len(data), "uri": "data:application/octet-stream;base64," + base64.b64encode(data).decode()}],
    }
    (tmp_path / "lamp.gltf").write_text(json.dumps(document))
    scene = penumbra.Scene.load(tmp_path / "lamp.gltf")
    assert len(scene) == 2 and scene.source.endswith("lamp.gltf")
    assert len(penumbra.Scene.load(tmp_path / "lamp.gltf", merge=False)) == 4
    run_cli(cli, "run", "lamp.gltf", "--direct-only", "--out", "out", "--quiet", cwd=tmp_path)
    assert penumbra.run(scene, direct_only=True).solution_json() == (tmp_path / "out" / "solution.json").read_text()


def test_scene_errors_carry_every_problem_as_check_reports_them(cli, tmp_path):
    # A repeated name, a degenerate triangle and a reflectance above 1.
    scene_json = (
        '{"name": "bad", "surfaces": ['
        '{"name": "light", "polygon": [[-0.5,-0.5,2],[-0.5,0.5,2],[0.5,0.5,2],[0.5,-0.5,2]],'
        ' "emission": [10,10,10], "reflectance": [0,0,0]},'
        '{"name": "light", "polygon": [[0,0,0],[1,0,0],[2,0,0]], "reflectance": [1.5,0.5,0.5]}]}'
    )
    (tmp_path / "bad.json").write_text(scene_json)
    check = subprocess.run([str(cli), "check", "bad.json"], cwd=tmp_path, capture_output=True, text=True)
    assert check.returncode == 2
    with pytest.raises(penumbra.SceneError) as raised:
        penumbra.Scene.load(tmp_path / "bad.json")
    problems = raised.value.problems
    assert len(problems) >= 3, problems
    for problem in problems:
        assert problem in check.stderr
    assert isinstance(raised.value, ValueError)
    with pytest.raises(penumbra.SceneError) as again:
        penumbra.Scene.from_json(scene_json)
    assert again.value.problems == problems
    with pytest.raises(penumbra.SceneError) as built:
        two_surfaces(polygons=[LIGHT, [[0, 0, 0], [1, 0, 0], [2, 0, 0]]], names=["light", "light"],
                     reflectance=[[0, 0, 0], [1.5, 0.5, 0.5]])
    assert built.value.problems == problems


def test_unknown_and_missing_scenes_say_so(tmp_path):
    with pytest.raises(penumbra.SceneError, match="built-in scenes are: cornell"):
        penumbra.Scene.builtin("cornel")
    with pytest.raises(FileNotFoundError, match="nowhere.json"):
        penumbra.Scene.load(tmp_path / "nowhere.json")
    (tmp_path / "scene.txt").write_text("{}")
    with pytest.raises(penumbra.SceneError, match="unsupported file type"):
        penumbra.Scene.load(tmp_path / "scene.txt")
    with pytest.raises(penumbra.SceneError, match=r"<json>:1:\d+"):
        penumbra.Scene.from_json("{not json")
    # A file called like a built-in scene is a file, and the name alone is not a path.
    with pytest.raises(FileNotFoundError):
        penumbra.Scene.load("cornell")


def test_locate_finds_the_surface_a_point_lies_on():
    scene = two_surfaces()
    ids = scene.locate([[0.3, 0.2, 0], [0, 0, 2], [0, 0, 1], [3, 0, 0], [2, 2, 0]])
    assert ids.tolist() == [1, 0, -1, -1, 1]


def test_frames_and_cameras():
    scene = two_surfaces()
    frame = scene.frame("floor")
    assert np.allclose(frame["normal"], [0, 0, 1])
    assert np.isclose(frame["u"] @ frame["v"], 0) and np.isclose(np.linalg.norm(frame["u"]), 1)
    assert np.allclose(np.cross(frame["u"], frame["v"]), frame["normal"])
    assert np.array_equal(scene.frame(1)["origin"], frame["origin"])
    with pytest.raises(IndexError):
        scene.frame(2)
    assert np.array_equal(scene.frame(-1)["u"], frame["u"])
    seen = scene.with_camera([0, -3, 1], [0, 0, 0], fov_deg=60)
    assert seen.camera == {"eye": [0, -3, 1], "target": [0, 0, 0], "up": [0, 0, 1], "fov_deg": 60.0}
    assert scene.camera is None and seen.fingerprint != scene.fingerprint  # the camera is part of it
    with pytest.raises(penumbra.SceneError, match="camera"):
        scene.with_camera([0, 0, 0], [0, 0, 0])
    # Parts not given stay the scene's, as with --eye alone on the command line.
    cornell = penumbra.Scene.builtin("cornell")
    closer = cornell.with_camera(eye=[278, 273, -500])
    assert closer.camera == dict(cornell.camera, eye=[278, 273, -500])
    # The render follows the camera: from below the floor it shows the floor's back, black.
    below = penumbra.run(scene.with_camera([1.5, 0, -1], [0, 0, 0]), direct_only=True, width=32, height=32)
    above = penumbra.run(scene.with_camera([1.5, 0, 1], [0, 0, 0]), direct_only=True, width=32, height=32)
    assert below.render().shape == (32, 32, 3)
    assert below.render().max() == 0 and above.render().max() > 100
