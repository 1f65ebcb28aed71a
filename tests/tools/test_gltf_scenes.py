"""glTF scenes in: a Cornell box laid out as Blender exports it (metres, +y up, a node per object,
emission as radiance) lights as the built-in one does, and broken files are refused with exit 2
and a message that names what is wrong."""

import importlib.machinery
import importlib.util
import json
import shutil
import struct
import subprocess
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[2]


def _script():
    """scripts/blender-like-glb as a module (it has no .py suffix)."""
    path = ROOT / "scripts" / "blender-like-glb"
    loader = importlib.machinery.SourceFileLoader("blender_like_glb", str(path))
    spec = importlib.util.spec_from_loader(loader.name, loader)
    module = importlib.util.module_from_spec(spec)
    loader.exec_module(module)
    return module


blender_like = _script()


def run(cli: Path, *arguments: str, cwd: Path) -> subprocess.CompletedProcess:
    return subprocess.run([str(cli), *arguments], cwd=cwd, capture_output=True, text=True)


@pytest.fixture(scope="module")
def cornell_json(penumbra_cli, tmp_path_factory) -> dict:
    out = tmp_path_factory.mktemp("cornell")
    done = run(penumbra_cli, "scenes", "--dump", "cornell", cwd=out)
    assert done.returncode == 0, done.stderr
    return json.loads(done.stdout)


def surface_means(solution: Path, name_of) -> dict[str, np.ndarray]:
    """Each surface's area-weighted mean radiosity (RGB), the surfaces grouped by `name_of`."""
    sums: dict[str, list] = {}
    for s in json.loads(solution.read_text())["surfaces"]:
        v = np.array(s["vertices"], dtype=float).reshape(-1, 3)
        b = np.array(s["radiosity"], dtype=float).reshape(-1, 3)
        t = np.array(s["triangles"], dtype=int).reshape(-1, 3)
        area = 0.5 * np.linalg.norm(np.cross(v[t[:, 1]] - v[t[:, 0]], v[t[:, 2]] - v[t[:, 0]]), axis=1)
        entry = sums.setdefault(name_of(s["name"]), [np.zeros(3), 0.0])
        entry[0] += (area[:, None] * b[t].mean(axis=1)).sum(axis=0)
        entry[1] += area.sum()
    return {name: total / area for name, (total, area) in sums.items()}


def test_a_blender_like_cornell_box_lights_as_the_built_in_one(penumbra_cli, cornell_json, tmp_path):
    document, binary = blender_like.gltf_document(cornell_json, 0.001)
    (tmp_path / "cornell.glb").write_bytes(blender_like.glb(document, binary))
    for source, out in (("cornell.glb", "from-gltf"), ("cornell", "built-in")):
        done = run(penumbra_cli, "run", source, "--out", out, "--quiet", cwd=tmp_path)
        assert done.returncode == 0, done.stderr
    # glTF surfaces are named node/material/index; the nodes are the built-in surfaces' names.
    from_gltf = surface_means(tmp_path / "from-gltf" / "solution.json", lambda n: n.rsplit("/", 2)[0])
    built_in = surface_means(tmp_path / "built-in" / "solution.json", lambda n: n)
    assert sorted(from_gltf) == sorted(built_in)
    for name, mean in built_in.items():
        assert from_gltf[name] == pytest.approx(mean, rel=0.01), name
    # The file's camera node is the render's camera: the built-in one, in metres.
    camera = json.loads((tmp_path / "from-gltf" / "report.json").read_text())["render"]["camera"]
    built_in_camera = cornell_json["camera"]
    assert np.allclose(camera["eye"], np.array(built_in_camera["eye"]) * 0.001, atol=1e-6)
    view = np.array(camera["target"]) - np.array(camera["eye"])
    assert np.allclose(view / np.linalg.norm(view), [0, 0, 1], atol=1e-6)
    assert np.allclose(camera["up"], built_in_camera["up"], atol=1e-6)
    assert camera["fov_deg"] == pytest.approx(built_in_camera["fov_deg"], rel=1e-6)


def test_the_khronos_validator_passes_the_test_scene(cornell_json, tmp_path):
    node = shutil.which("node")
    assert node, "the glTF validator runs on Node.js"
    document, binary = blender_like.gltf_document(cornell_json, 0.001)
    (tmp_path / "cornell.glb").write_bytes(blender_like.glb(document, binary))
    script = Path(__file__).with_name("validate_gltf.js")
    done = subprocess.run([node, str(script), str(tmp_path / "cornell.glb")], capture_output=True, text=True, check=True)
    issues = json.loads(done.stdout)
    assert issues["numErrors"] == 0 and issues["numWarnings"] == 0, issues["messages"]


def _truncated(document, binary, tmp_path):
    data = blender_like.glb(document, binary)
    (tmp_path / "scene.glb").write_bytes(data[: len(data) - 200])
    return "scene.glb"


def _index_out_of_range(document, binary, tmp_path):
    view = document["bufferViews"][document["accessors"][document["meshes"][2]["primitives"][0]["indices"]]["bufferView"]]
    patched = bytearray(binary)
    struct.pack_into("<H", patched, view["byteOffset"] + 2, 99)
    (tmp_path / "scene.glb").write_bytes(blender_like.glb(document, bytes(patched)))
    return "scene.glb"


def _nan_position(document, binary, tmp_path):
    view = document["bufferViews"][document["accessors"][document["meshes"][1]["primitives"][0]["attributes"]["POSITION"]]["bufferView"]]
    patched = bytearray(binary)
    struct.pack_into("<f", patched, view["byteOffset"] + 16, float("nan"))
    (tmp_path / "scene.glb").write_bytes(blender_like.glb(document, bytes(patched)))
    return "scene.glb"


def _missing_bin(document, binary, tmp_path):
    document = dict(document, buffers=[{"byteLength": len(binary), "uri": "scene.bin"}])
    (tmp_path / "scene.gltf").write_text(json.dumps(document))
    return "scene.gltf"


@pytest.mark.parametrize(
    "broken, says",
    [
        (_truncated, ["scene.glb", "truncated"]),
        (_index_out_of_range, ["indices of mesh \"back_wall\"", "node \"back_wall\"", "index 99"]),
        (_nan_position, ["POSITION of mesh \"ceiling\"", "node \"ceiling\"", "not a finite number"]),
        (_missing_bin, ["buffer 0", "scene.bin"]),
    ],
    ids=["truncated", "index-out-of-range", "nan-position", "missing-bin"],
)
def test_a_broken_file_exits_2_naming_what_is_wrong(penumbra_cli, cornell_json, tmp_path, broken, says):
    document, binary = blender_like.gltf_document(cornell_json, 0.001)
    name = broken(document, binary, tmp_path)
    for command in (["check", name], ["run", name, "--out", "out", "--quiet"]):
        done = run(penumbra_cli, *command, cwd=tmp_path)
        assert done.returncode == 2, (command, done.stderr)
        for words in says:
            assert words in done.stderr, (command, done.stderr)
        assert "panicked" not in done.stderr
    assert not (tmp_path / "out").exists()


def _validate(path: Path) -> None:
    node = shutil.which("node")
    assert node, "the glTF validator runs on Node.js"
    script = Path(__file__).with_name("validate_gltf.js")
    done = subprocess.run([node, str(script), str(path)], capture_output=True, text=True, check=True)
    issues = json.loads(done.stdout)
    assert issues["numErrors"] == 0 and issues["numWarnings"] == 0, issues["messages"]


def _mesh_bounds(path: Path) -> np.ndarray:
    """The box around the triangles of a .glb, in its world frame (node transforms applied)."""
    import trimesh

    scene = trimesh.load(str(path))
    meshes = [
        g.copy().apply_transform(scene.graph.get(node)[0])
        for node in scene.graph.nodes_geometry
        if isinstance((g := scene.geometry[scene.graph.get(node)[1]]), trimesh.Trimesh)
    ]
    return trimesh.util.concatenate(meshes).bounds


def test_the_export_of_a_gltf_scene_overlays_it(penumbra_cli, cornell_json, tmp_path):
    document, binary = blender_like.gltf_document(cornell_json, 0.001)
    (tmp_path / "cornell.glb").write_bytes(blender_like.glb(document, binary))
    done = run(penumbra_cli, "run", "cornell.glb", "--out", "out", "--quiet", "--export", "glb", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    exported = tmp_path / "out" / "solution.glb"
    _validate(exported)
    assert np.allclose(_mesh_bounds(exported), _mesh_bounds(tmp_path / "cornell.glb"), atol=1e-6)
    import pygltflib

    names = {n.name for n in pygltflib.GLTF2().load(str(exported)).nodes}
    assert {n["name"] for n in document["nodes"] if "mesh" in n} <= names


def test_a_z_up_scene_in_millimetres_exports_in_metres_with_y_up(penumbra_cli, cornell_json, tmp_path):
    # The Cornell box turned +z up, (x, y, z) -> (x, -z, y), in millimetres.
    turn = lambda p: [p[0], -p[2], p[1]]
    scene = json.loads(json.dumps(cornell_json))
    for s in scene["surfaces"]:
        s["polygon"] = [turn(p) for p in s["polygon"]]
    camera = scene["camera"]
    for key in ("eye", "target", "up"):
        camera[key] = turn(camera[key])
    scene["unit"] = "mm"
    scene["up"] = [0, 0, 1]
    (tmp_path / "z-up.json").write_text(json.dumps(scene))
    document, binary = blender_like.gltf_document(cornell_json, 0.001)
    (tmp_path / "cornell.glb").write_bytes(blender_like.glb(document, binary))
    done = run(penumbra_cli, "run", "z-up.json", "--out", "out", "--quiet", "--export", "glb", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    report = json.loads((tmp_path / "out" / "report.json").read_text())
    assert report["scene"]["up"] == [0, 0, 1] and report["scene"]["unit"] == "mm"
    exported = tmp_path / "out" / "solution.glb"
    _validate(exported)
    # It lands where the +y-up box in metres stands.
    assert np.allclose(_mesh_bounds(exported), _mesh_bounds(tmp_path / "cornell.glb"), atol=1e-6)
