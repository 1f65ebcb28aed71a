"""The exports of `penumbra run --export`, read back by the readers their users have: VTK
(ParaView's library) for solution.vtp, plyfile for solution.ply, pygltflib and trimesh for
solution.glb. Counts, values to the bit against solution.json, and the discontinuity classes."""

import json
import shutil
import subprocess
from pathlib import Path

import numpy as np
import plyfile
import pygltflib
import pytest
import trimesh
import vtk
from vtk.util.numpy_support import vtk_to_numpy

ROOT = Path(__file__).resolve().parents[2]
EVENTS = ["EV", "VE", "EEE", "contact", "blocker-EV", "horizon"]
BOUNDARIES = ["umbra", "penumbra", "inner"]


def run(cli: Path, out: Path, *options: str) -> None:
    subprocess.run([str(cli), "run", "cornell", "--out", str(out), "--quiet", *options], check=True)


class Solution:
    """solution.json and report.json, joined over the surfaces as the exports join them."""

    def __init__(self, out: Path):
        self.json = json.loads((out / "solution.json").read_text())
        self.report = json.loads((out / "report.json").read_text())
        surfaces = self.json["surfaces"]
        self.counts = [len(s["vertices"]) for s in surfaces]
        offsets = np.cumsum([0] + self.counts)[:-1]
        cat = lambda field: np.concatenate(  # noqa: E731
            [np.array(s[field], dtype=float).reshape(-1, 3) for s in surfaces]
        )
        self.vertices = cat("vertices")
        self.radiosity = cat("radiosity")
        self.direct = cat("direct")
        emission = np.repeat([s["emission"] for s in surfaces], self.counts, axis=0)
        self.reflectance = np.repeat([s["reflectance"] for s in surfaces], self.counts, axis=0)
        self.indirect = self.radiosity - emission - self.direct
        self.triangles = np.concatenate(
            [np.array(s["triangles"], dtype=np.int64).reshape(-1, 3) + o for s, o in zip(surfaces, offsets)]
        )
        self.triangle_surface = np.repeat(np.arange(len(surfaces)), [len(s["triangles"]) for s in surfaces])
        self.lines = [(i, d) for i, s in enumerate(surfaces) for d in s["discontinuities"]]
        self.error = (
            np.concatenate([s["error_indicator"] for s in surfaces])
            if all("error_indicator" in s for s in surfaces)
            else None
        )
        render = self.report["render"]
        self.exposure = render["exposure"]
        self.ambient = np.array(render["ambient"])

    def luminance(self) -> np.ndarray:
        r, g, b = self.radiosity.T
        return 0.2126 * r + 0.7152 * g + 0.0722 * b

    def shown(self) -> np.ndarray:
        """What render.png shows, before the exposure: B plus each surface's share of the
        ambient term, rho * ambient."""
        return self.radiosity + self.reflectance * self.ambient

    def srgb8(self) -> np.ndarray:
        """render.png's colours: the sRGB curve of (B + rho * ambient) * exposure, in 8 bits."""
        v = np.clip(self.shown() * self.exposure, 0.0, 1.0)
        encoded = np.where(v <= 0.0031308, 12.92 * v, 1.055 * v ** (1 / 2.4) - 0.055)
        return np.round(encoded * 255.0).astype(np.uint8)


@pytest.fixture(scope="module")
def exported(penumbra_cli, tmp_path_factory):
    out = tmp_path_factory.mktemp("cornell")
    run(penumbra_cli, out, "--max-elements", "4000", "--export", "vtp,ply,glb,obj")
    return out, Solution(out)


@pytest.fixture(scope="module")
def direct(penumbra_cli, tmp_path_factory):
    """Direct light only: the render shows an ambient term, the colours must too."""
    out = tmp_path_factory.mktemp("direct")
    run(penumbra_cli, out, "--max-elements", "4000", "--direct-only", "--export", "ply,glb")
    solution = Solution(out)
    assert (solution.ambient > 0).all()
    return out, solution


@pytest.fixture(scope="module")
def adaptive(penumbra_cli, tmp_path_factory):
    out = tmp_path_factory.mktemp("adaptive")
    run(penumbra_cli, out, "--max-elements", "6000", "--refine-tol", "0.05", "--solver", "progressive", "--export", "vtp")
    return out, Solution(out)


def read_vtp(path: Path):
    reader = vtk.vtkXMLPolyDataReader()
    reader.SetFileName(str(path))
    reader.Update()
    return reader.GetOutput()


def array(data, name: str) -> np.ndarray:
    found = data.GetArray(name)
    assert found is not None, f"no array {name}"
    return vtk_to_numpy(found)


def test_vtk_reads_the_mesh_values_and_lines(exported):
    out, solution = exported
    poly = read_vtp(out / "solution.vtp")
    lines = len(solution.lines)
    n = len(solution.vertices)
    assert poly.GetNumberOfPoints() == n + 2 * lines
    assert poly.GetNumberOfPolys() == len(solution.triangles)
    assert poly.GetNumberOfLines() == lines
    # The mesh's vertices, then each segment's ends where solution.json puts them.
    points = vtk_to_numpy(poly.GetPoints().GetData())
    ends = np.array([[d["from"], d["to"]] for _, d in solution.lines]).reshape(-1, 3)
    assert np.array_equal(points, np.vstack([solution.vertices, ends]))
    line_points = vtk_to_numpy(poly.GetLines().GetConnectivityArray())
    assert np.array_equal(line_points, n + np.arange(2 * lines))
    # A segment end carries the values of the mesh vertex it was built into: the nearest one
    # on its surface, within the mesh's welding of close ends.
    surface_of = np.repeat([s for s, _ in solution.lines], 2)
    vertex_surface = np.repeat(np.arange(len(solution.counts)), solution.counts)
    size = np.ptp(solution.vertices, axis=0).max()
    radiosity = array(poly.GetPointData(), "radiosity")
    for end, s, value in zip(ends, surface_of, radiosity[n:]):
        on = np.flatnonzero(vertex_surface == s)
        d = np.linalg.norm(solution.vertices[on] - end, axis=1)
        assert d.min() < 1e-6 * size
        assert any(np.array_equal(value, solution.radiosity[v]) for v in on[d == d.min()])
    points = poly.GetPointData()
    assert np.array_equal(array(points, "radiosity")[:n], solution.radiosity)
    assert np.array_equal(array(points, "direct")[:n], solution.direct)
    assert np.array_equal(array(points, "indirect")[:n], solution.indirect)
    assert np.array_equal(array(points, "luminance")[:n], solution.luminance())
    # VTK orders cells lines first, then polygons.
    polys = vtk_to_numpy(poly.GetPolys().GetConnectivityArray()).reshape(-1, 3)
    assert np.array_equal(polys, solution.triangles)
    cells = poly.GetCellData()
    surface = array(cells, "surface")
    assert np.array_equal(surface[lines:], solution.triangle_surface)
    assert np.array_equal(surface[:lines], [s for s, _ in solution.lines])
    for name, names in [("event", EVENTS), ("boundary", BOUNDARIES)]:
        codes = array(cells, name)
        assert [names[c] for c in codes[:lines]] == [d[name] for _, d in solution.lines]
        assert (codes[lines:] == -1).all()
    order = array(cells, "order")
    assert list(order[:lines]) == [d["order"] for _, d in solution.lines]
    assert set(order[:lines]) == {0, 1, 2}, "the Cornell box has lines of every class"


def test_vtk_reads_the_error_indicator_of_an_adaptive_run(adaptive):
    out, solution = adaptive
    assert solution.error is not None and len(solution.error) == len(solution.triangles)
    poly = read_vtp(out / "solution.vtp")
    error = array(poly.GetCellData(), "error_indicator")
    lines = len(solution.lines)
    assert np.isnan(error[:lines]).all()
    assert np.array_equal(error[lines:], solution.error)
    assert (solution.error >= 0).all() and solution.error.max() > 0


@pytest.mark.parametrize("run", ["exported", "direct"])
def test_plyfile_reads_positions_colours_and_quality(request, run):
    out, solution = request.getfixturevalue(run)
    ply = plyfile.PlyData.read(str(out / "solution.ply"))
    assert not ply.text and ply.byte_order == "<", "binary little endian"
    v = ply["vertex"].data
    assert len(v) == len(solution.vertices)
    assert np.array_equal(np.c_[v["x"], v["y"], v["z"]], solution.vertices)
    assert np.array_equal(np.c_[v["red"], v["green"], v["blue"]], solution.srgb8())
    assert np.array_equal(v["quality"], solution.luminance())
    faces = ply["face"].data
    assert np.array_equal(np.vstack(faces["vertex_indices"]), solution.triangles)
    assert np.array_equal(faces["surface"], solution.triangle_surface)


@pytest.mark.parametrize("run", ["exported", "direct"])
def test_pygltflib_reads_a_mesh_per_object_and_a_lines_primitive_per_class(request, run):
    out, solution = request.getfixturevalue(run)
    gltf = pygltflib.GLTF2().load(str(out / "solution.glb"))
    blob = gltf.binary_blob()

    def read(accessor_index: int, dtype, width: int) -> np.ndarray:
        accessor = gltf.accessors[accessor_index]
        view = gltf.bufferViews[accessor.bufferView]
        start = (view.byteOffset or 0) + (accessor.byteOffset or 0)
        values = np.frombuffer(blob, dtype=dtype, count=accessor.count * width, offset=start)
        return values.reshape(accessor.count, width) if width > 1 else values

    *objects, lines = gltf.meshes
    assert lines.name == "discontinuities"
    # The Cornell box's surface names have no `/`: each surface is an object of its own.
    assert [m.name for m in objects] == [s["name"] for s in json.loads((out / "solution.json").read_text())["surfaces"]]
    assert "KHR_materials_unlit" in gltf.extensionsUsed
    parts: dict[str, list] = {}
    offset = 0
    for mesh in objects:
        (triangles,) = mesh.primitives
        assert triangles.mode == pygltflib.TRIANGLES
        attributes = triangles.attributes
        for name in ("POSITION", "COLOR_0", "_RADIOSITY", "_DIRECT", "_INDIRECT"):
            parts.setdefault(name, []).append(read(getattr(attributes, name), "<f4", 3))
        parts.setdefault("indices", []).append(read(triangles.indices, "<u4", 1).reshape(-1, 3) + offset)
        offset += gltf.accessors[attributes.POSITION].count
    whole = {name: np.concatenate(values) for name, values in parts.items()}
    assert np.array_equal(whole["POSITION"], solution.vertices.astype(np.float32))
    assert np.array_equal(whole["_RADIOSITY"], solution.radiosity.astype(np.float32))
    assert np.array_equal(whole["_DIRECT"], solution.direct.astype(np.float32))
    assert np.array_equal(whole["_INDIRECT"], solution.indirect.astype(np.float32))
    linear = np.clip(solution.shown() * solution.exposure, 0, 1)
    assert np.array_equal(whole["COLOR_0"], linear.astype(np.float32))
    assert np.array_equal(whole["indices"], solution.triangles)
    classes = {p.extras["class"]: p for p in lines.primitives}
    assert sorted(classes) == ["D0", "D1", "D2"]
    for order in range(3):
        primitive = classes[f"D{order}"]
        assert primitive.mode == pygltflib.LINES
        segments = [d for _, d in solution.lines if d["order"] == order]
        ends = read(primitive.attributes.POSITION, "<f4", 3).reshape(-1, 2, 3)
        given = np.array([[d["from"], d["to"]] for d in segments], dtype=np.float32)
        assert np.array_equal(ends, given)


def test_trimesh_loads_the_glb_as_a_scene(exported):
    out, solution = exported
    scene = trimesh.load(str(out / "solution.glb"))
    meshes = [g for g in scene.geometry.values() if isinstance(g, trimesh.Trimesh)]
    paths = [g for g in scene.geometry.values() if not isinstance(g, trimesh.Trimesh)]
    assert len(meshes) == 17 and len(paths) == 3  # a mesh per surface of the Cornell box
    mesh = trimesh.util.concatenate(meshes)
    assert len(mesh.faces) == len(solution.triangles)
    # trimesh merges nothing it was not asked to: the vertex count is the solution's.
    assert len(mesh.vertices) == len(solution.vertices)
    # Its area is the scene's meshed area.
    v, t = solution.vertices, solution.triangles
    area = 0.5 * np.linalg.norm(np.cross(v[t[:, 1]] - v[t[:, 0]], v[t[:, 2]] - v[t[:, 0]]), axis=1).sum()
    assert mesh.area == pytest.approx(area, rel=1e-6)


def test_the_khronos_validator_finds_no_issue(exported):
    out, _ = exported
    node = shutil.which("node")
    assert node, "the glTF validator runs on Node.js"
    assert (ROOT / "viewer" / "node_modules" / "gltf-validator").is_dir(), "run viewer/build (npm ci) first"
    script = Path(__file__).with_name("validate_gltf.js")
    done = subprocess.run([node, str(script), str(out / "solution.glb")], capture_output=True, text=True, check=True)
    issues = json.loads(done.stdout)
    assert issues["numErrors"] == 0 and issues["numWarnings"] == 0, issues["messages"]
    assert issues["numInfos"] == 0 and issues["numHints"] == 0, issues["messages"]
