"""Transform: Mitsuba's composition order and the XML reader's operations."""

import numpy as np
import pytest

import prism_renderer as pr

T = pr.Transform


def apply(t: pr.Transform, point) -> np.ndarray:
    return (t.matrix @ np.array([*point, 1.0]))[:3]


def test_operations_compose_on_the_right_as_in_mitsuba():
    t = T().translate([1, 2, 3]).scale(2)
    assert np.allclose(apply(t, [1, 1, 1]), [3, 4, 5])
    assert t == T().translate([1, 2, 3]) @ T().scale([2, 2, 2])
    assert np.allclose((t @ t.inverse()).matrix, np.eye(4))


def test_rotate_is_right_handed_in_degrees():
    assert np.allclose(apply(T().rotate([0, 0, 1], 90), [1, 0, 0]), [0, 1, 0])
    with pytest.raises(ValueError, match="zero rotation axis"):
        T().rotate([0, 0, 0], 90)


def test_rotate_takes_its_axis_as_given_as_mitsuba_3():
    # About a = (0, 0, 2) by θ = 90°, the matrix also scales by |a| = 2 across the axis and by
    # cos θ + (1 - cos θ) |a|² = 4 along it.
    assert np.allclose(apply(T().rotate([0, 0, 2], 90), [1, 0, 0]), [0, 2, 0])
    assert np.allclose(apply(T().rotate([0, 0, 2], 90), [0, 0, 1]), [0, 0, 4])


def test_look_at_has_mitsubas_columns():
    m = T().look_at(origin=[0, 0, 5], target=[0, 0, 0], up=[0, 1, 0]).matrix
    assert np.allclose(m[:3, 2], [0, 0, -1])  # the view direction
    assert np.allclose(m[:3, 1], [0, 1, 0])  # up
    assert np.allclose(m[:3, 0], [-1, 0, 0])  # left = up × direction
    assert np.allclose(m[:3, 3], [0, 0, 5])
    with pytest.raises(ValueError, match="coincide"):
        T().look_at(origin=[1, 1, 1], target=[1, 1, 1])


def test_a_matrix_round_trips():
    m = np.arange(16.0).reshape(4, 4)
    assert np.array_equal(T(m).matrix, m)
    with pytest.raises(ValueError):
        T(np.eye(3))


def test_a_transform_in_a_dictionary_equals_the_same_xml_transform(tmp_path):
    xml = tmp_path / "scene.xml"
    xml.write_text(
        '<scene version="3.0.0">'
        '<sensor type="perspective"><transform name="to_world">'
        '<lookat origin="0, 0, 4" target="0, 0, 0" up="0, 1, 0"/></transform>'
        '<film type="hdrfilm"><integer name="width" value="16"/>'
        '<integer name="height" value="12"/></film></sensor>'
        '<shape type="sphere"><transform name="to_world">'
        '<scale value="0.5"/><rotate y="1" angle="30"/><translate x="0.3"/></transform></shape>'
        '<emitter type="constant"/></scene>'
    )
    scene = {
        "type": "scene",
        "sensor": {
            "type": "perspective",
            "to_world": T().look_at(origin=[0, 0, 4], target=[0, 0, 0], up=[0, 1, 0]),
            "film": {"type": "hdrfilm", "width": 16, "height": 12},
        },
        "ball": {
            "type": "sphere",
            "to_world": T().translate([0.3, 0, 0]).rotate([0, 1, 0], 30).scale(0.5),
        },
        "sky": {"type": "constant"},
    }
    a = pr.render(pr.load_file(xml), spp=2, progress=False)
    b = pr.render(pr.load_dict(scene), spp=2, progress=False)
    assert np.array_equal(a.xyz, b.xyz)
