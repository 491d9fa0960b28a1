"""What a scene is made of: `scene.shapes()`, `emitters()`, `sensors()` and `bbox()`, and each
shape's name, box, area and mesh arrays, against the Cornell box's OBJ files and closed
forms."""

import math
from pathlib import Path

import numpy as np
import pytest

import prism_renderer as pr


def _obj(path: Path):
    """The vertices and the faces (0-based, fans of triangles) of a small OBJ file."""
    vertices: list = []
    faces: list = []
    for line in path.read_text().splitlines():
        parts = line.split()
        if parts and parts[0] == "v":
            vertices.append([float(v) for v in parts[1:4]])
        elif parts and parts[0] == "f":
            corners = [int(p.split("/")[0]) - 1 for p in parts[1:]]
            faces.extend([corners[0], corners[i], corners[i + 1]] for i in range(1, len(corners) - 1))
    return np.array(vertices), np.array(faces)


def _triangle_areas(vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    a, b, c = (vertices[faces[:, i]] for i in range(3))
    return 0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1)


def test_the_cornell_boxs_shapes_are_its_meshes(cornell, cornell_path):
    shapes = cornell.shapes()
    # The file's meshes in document order, the light last.
    names = [line.split('"')[-2] for line in cornell_path.read_text().splitlines()
             if 'name="filename"' in line]
    assert len(names) == 8 and Path(names[-1]).stem == "light"
    assert [shape.id() for shape in shapes] == [f"shape_{i}" for i in range(8)]
    assert [shape.index for shape in shapes] == list(range(8))
    everything = []
    for shape, name in zip(shapes, names):
        vertices, faces = _obj(cornell_path.parent / name)
        assert shape.is_mesh() and shape.plugin_type() == "obj"
        positions = shape.vertex_positions()
        assert positions.dtype == np.float32 and positions.shape == (shape.vertex_count(), 3)
        assert shape.faces().dtype == np.uint32 and shape.faces().shape == (shape.face_count(), 3)
        # The same triangles, whatever the order of the vertices.
        ours = np.sort(positions[shape.faces()].reshape(-1, 9), axis=0)
        theirs = np.sort(vertices[faces].reshape(-1, 9), axis=0)
        np.testing.assert_allclose(ours, theirs, rtol=1e-6)
        area = _triangle_areas(vertices, faces).sum()
        assert shape.surface_area() == pytest.approx(area, rel=1e-5)
        box = shape.bbox()
        np.testing.assert_allclose(box.min, vertices.min(0), rtol=1e-6)
        np.testing.assert_allclose(box.max, vertices.max(0), rtol=1e-6)
        everything.append(vertices)
    every = np.concatenate(everything)
    box = cornell.bbox()
    np.testing.assert_allclose(box.min, every.min(0), atol=1e-4)
    np.testing.assert_allclose(box.max, every.max(0), atol=1e-4)
    np.testing.assert_allclose(box.center(), (every.min(0) + every.max(0)) / 2, atol=1e-4)
    np.testing.assert_allclose(box.extents(), every.max(0) - every.min(0), atol=1e-4)
    # One light, on the last mesh.
    assert [shape.is_emitter() for shape in shapes] == [False] * 7 + [True]
    (light,) = cornell.emitters()
    assert light.shape() == 7 and not light.is_environment()
    assert light.id() == "shape_7.emitter"
    assert "shape_7.emitter.radiance.values" in pr.traverse(cornell).keys()
    (sensor,) = cornell.sensors()
    assert sensor.id() is None and sensor.film_size() == (cornell.width, cornell.height)


def test_mitsubas_cornell_box_dictionary_names_its_shapes_by_their_keys():
    scene = pr.load_dict(pr.cornell_box())
    keys = [key for key in pr.cornell_box() if key not in ("type", "integrator", "sensor")]
    shapes = [key for key in keys if pr.cornell_box()[key]["type"] in ("rectangle", "cube")]
    assert [shape.id() for shape in scene.shapes()] == shapes
    (light,) = scene.emitters()
    assert light.id() == "light.emitter" and scene.shapes()[light.shape()].id() == "light"


def test_named_shapes_analytic_shapes_and_every_sensor():
    scene = pr.load_string("""<scene version="3.0.0">
        <sensor type="perspective" id="front"><film type="hdrfilm"><integer name="width" value="8"/>
            <integer name="height" value="6"/></film></sensor>
        <sensor type="perspective"><film type="hdrfilm"><integer name="width" value="5"/>
            <integer name="height" value="4"/></film></sensor>
        <shape type="sphere" id="ball"><point name="center" x="1" y="2" z="3"/>
            <float name="radius" value="0.5"/></shape>
        <shape type="disk"><transform name="to_world"><scale value="2"/></transform></shape>
        <shape type="rectangle"><emitter type="area"/></shape>
        <emitter type="constant"/>
    </scene>""")
    ball, disk, rectangle = scene.shapes()
    # The names traverse gives them: the keys of their parameters.
    assert [ball.id(), disk.id(), rectangle.id()] == ["ball", "shape_0", "shape_1"]
    keys = pr.traverse(scene).keys()
    assert "ball.radius" in keys and "shape_0.to_world" in keys
    assert [s.plugin_type() for s in scene.shapes()] == ["sphere", "disk", "rectangle"]
    assert ball.surface_area() == pytest.approx(4 * math.pi * 0.25, rel=1e-6)
    assert disk.surface_area() == pytest.approx(math.pi * 4, rel=1e-6)
    assert rectangle.surface_area() == pytest.approx(4, rel=1e-6)
    np.testing.assert_allclose(ball.bbox().min, [0.5, 1.5, 2.5], rtol=1e-6)
    np.testing.assert_allclose(ball.bbox().max, [1.5, 2.5, 3.5], rtol=1e-6)
    assert not ball.is_mesh() and rectangle.is_mesh()
    with pytest.raises(TypeError, match="sphere.*not a triangle mesh"):
        ball.vertex_positions()
    area, environment = scene.emitters()
    assert (area.id(), area.shape(), area.is_environment()) == ("shape_1.emitter", 2, False)
    assert (environment.id(), environment.shape(), environment.is_environment()) == (
        "emitter", None, True)
    front, second = scene.sensors()
    assert (front.id(), front.film_size()) == ("front", (8, 6))
    assert (second.id(), second.film_size()) == (None, (5, 4))
