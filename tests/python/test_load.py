"""Scenes from files and from dictionaries: the same scene either way, and bad input raising
PrismError at the right place."""

import numpy as np
import pytest

import prism_renderer as pr
from conftest import SIZE


def assert_same_image(a: pr.Image, b: pr.Image) -> None:
    for name in ("rgb", "xyz", "variance", "relative_error"):
        assert np.array_equal(getattr(a, name), getattr(b, name)), name


def test_the_file_and_its_dictionary_render_identical_arrays(cornell, cornell_dict):
    from_dict = pr.load_dict(cornell_dict)
    assert (from_dict.width, from_dict.height, from_dict.spp) == (
        SIZE["resx"],
        SIZE["resy"],
        SIZE["spp"],
    )
    a = pr.render(cornell, seed=5, progress=False)
    b = pr.render(from_dict, seed=5, progress=False)
    assert a.rgb.shape == (SIZE["resy"], SIZE["resx"], 3)
    assert a.rgb.dtype == np.float32
    assert a.relative_error.shape == (SIZE["resy"], SIZE["resx"])
    assert a.xyz[..., 1].mean() > 0
    assert_same_image(a, b)


def test_a_transform_and_its_4x4_matrix_are_the_same_value(cornell_dict):
    as_list = dict(cornell_dict)
    as_list["sensor"] = dict(cornell_dict["sensor"])
    as_list["sensor"]["to_world"] = cornell_dict["sensor"]["to_world"].matrix.tolist()
    as_array = dict(as_list)
    as_array["sensor"] = dict(as_list["sensor"])
    as_array["sensor"]["to_world"] = np.array(as_list["sensor"]["to_world"])
    images = [
        pr.render(pr.load_dict(d), seed=1, spp=1, progress=False)
        for d in (cornell_dict, as_list, as_array)
    ]
    assert_same_image(images[0], images[1])
    assert_same_image(images[0], images[2])


def test_defines_set_the_scenes_defaults(cornell_path):
    scene = pr.load_file(cornell_path, spp=2, resx=8, resy=6, sampler="stratified")
    assert (scene.width, scene.height, scene.spp) == (8, 6, 2)


def write(tmp_path, text: str):
    path = tmp_path / "scene.xml"
    path.write_text(text)
    return path


def test_a_misspelled_parameter_in_a_file_names_its_line_and_column(tmp_path):
    path = write(
        tmp_path,
        '<scene version="3.0.0"><sensor type="perspective"/>\n'
        '    <shape type="sphere">\n'
        '        <float name="radiuss" value="1"/>\n'
        "    </shape>\n"
        "</scene>\n",
    )
    with pytest.raises(pr.PrismError) as raised:
        pr.load_file(path)
    error = raised.value
    assert error.file == str(path)
    assert (error.line, error.column) == (3, 9)
    assert "did you mean" in error.help and "radius" in error.help
    assert error.kind == "input"
    assert str(error).startswith(f"{path}:3:9: ")


def test_malformed_xml_names_its_place(tmp_path):
    path = write(tmp_path, '<scene version="3.0.0">\n  <shape type="sphere">\n</scene>\n')
    with pytest.raises(pr.PrismError) as raised:
        pr.load_file(path)
    assert raised.value.file == str(path)
    assert raised.value.line is not None and raised.value.line >= 2


def test_a_missing_file_is_a_prism_error(tmp_path):
    with pytest.raises(pr.PrismError) as raised:
        pr.load_file(tmp_path / "nothing.xml")
    assert raised.value.file is None or "nothing.xml" in raised.value.file
    assert "nothing.xml" in str(raised.value)


def scene_with(**entries) -> dict:
    return {
        "type": "scene",
        "sensor": {"type": "perspective", "film": {"type": "hdrfilm", "width": 4, "height": 4}},
        **entries,
    }


@pytest.mark.parametrize(
    "entries, key_path, words",
    [
        (
            {"ball": {"type": "sphere", "bsdf": {"type": "diffuse", "reflectanse": 0.5}}},
            "scene.ball.bsdf.reflectanse",
            'did you mean "reflectance"',
        ),
        ({"ball": {"type": "spere"}}, "scene.ball", 'did you mean "sphere"'),
        (
            {"ball": {"type": "sphere", "bsdf": {"type": "ref", "id": "nothing"}}},
            "scene.ball.bsdf",
            "unknown id",
        ),
        (
            {"b": {"type": "diffuse", "reflectance": {"type": "rgb", "value": [0.1, 0.2]}}},
            "scene.b.reflectance.value",
            "2 numbers",
        ),
        ({"ball": {"type": "sphere", "center": [1, 2]}}, "scene.ball.center", "list of 2"),
        ({"ball": {"type": "sphere", "radius": object()}}, "scene.ball.radius", "object"),
        ({"ball": {"radius": 1.0}}, "scene.ball", 'no "type"'),
    ],
)
def test_bad_dictionaries_name_the_key_path(entries, key_path, words):
    with pytest.raises(pr.PrismError) as raised:
        pr.load_dict(scene_with(**entries))
    error = raised.value
    assert error.file == key_path
    assert error.line is None and error.column is None
    assert words in str(error)


def test_a_dictionary_key_must_be_a_string():
    with pytest.raises(pr.PrismError) as raised:
        pr.load_dict({"type": "scene", 3: {"type": "sphere"}})
    assert raised.value.file == "scene"
    assert "not a string" in str(raised.value)


def test_the_root_must_be_a_scene():
    with pytest.raises(pr.PrismError, match='not "scene"'):
        pr.load_dict({"type": "sphere"})


def test_path_objects_and_numpy_values_are_read_as_their_values(cornell_dict, cornell):
    from pathlib import Path

    d = dict(cornell_dict)
    d["floor"] = dict(cornell_dict["floor"], filename=Path(cornell_dict["floor"]["filename"]))
    d["sensor"] = dict(cornell_dict["sensor"], fov=np.float64(39.3077))
    d["sensor"]["film"] = dict(cornell_dict["sensor"]["film"], width=np.int32(24))
    a = pr.render(pr.load_dict(d), seed=5, progress=False)
    assert_same_image(a, pr.render(cornell, seed=5, progress=False))


def test_a_dictionary_or_list_containing_itself_is_an_error():
    ball: dict = {"type": "sphere"}
    ball["bsdf"] = ball
    with pytest.raises(pr.PrismError, match="nested more than"):
        pr.load_dict(scene_with(ball=ball))
    center: list = [1.0, 2.0]
    center.append(center)
    with pytest.raises(pr.PrismError, match="nested more than"):
        pr.load_dict(scene_with(ball={"type": "sphere", "center": center}))


def test_a_pbrt_v4_scene_loads_by_its_name(cornell_path):
    """A `.pbrt` file is read as pbrt-v4 (docs/pbrt.md): the bundled transcription of the
    Cornell box renders, at 16 spp with an independent seed, an image whose mean Y is the XML's
    within four standard errors of the difference (pixels are independent, so the mean's
    variance is the sum of the pixels' over the count squared), and `-D`-style defines are
    refused for it."""
    pbrt = cornell_path.with_name("scene.pbrt")
    scene = pr.load_file(pbrt)
    image = pr.render(scene, spp=16, seed=1, progress=False)
    xml = pr.render(pr.load_file(cornell_path), spp=16, seed=2, progress=False)
    assert image.rgb.shape == xml.rgb.shape
    count = image.xyz[:, :, 1].size
    difference = image.xyz[:, :, 1].mean() - xml.xyz[:, :, 1].mean()
    variance = (image.variance[:, :, 1].sum() + xml.variance[:, :, 1].sum()) / count**2
    assert abs(difference) < 4 * np.sqrt(variance), (difference, np.sqrt(variance))
    with pytest.raises(pr.PrismError, match="no parameters to set"):
        pr.load_file(pbrt, spp=4)


def test_tensor_parameters_come_from_numpy_arrays():
    """Mitsuba's tensor parameters (`sdfgrid`'s `grid`, `ellipsoids`' `data`), which only a
    dictionary can give, read from numpy arrays: hits against their closed forms."""
    n = 5
    heights = np.linspace(0.0, 1.0, n) - 0.37  # the plane z = 0.37, reproduced exactly
    grid = np.broadcast_to(heights[:, None, None, None], (n, n, n, 1)).astype(np.float32)
    data = np.array([[3.0, 0.0, 0.0, 0.2, 0.4, 0.6, 0.0, 0.0, 0.0, 1.0]], dtype=np.float32)
    scene = pr.load_dict({
        "type": "scene",
        "sensor": {"type": "perspective"},
        "plane": {"type": "sdfgrid", "grid": grid},
        "cloud": {"type": "ellipsoids", "data": data, "extent": 1.0},
    })
    origins = np.array([[0.5, 0.5, 2.0], [3.0, 0.0, 2.0], [3.0, 2.0, 0.0], [5.0, 0.0, 0.0]])
    directions = np.array([[0, 0, -1], [0, 0, -1], [0, -1, 0], [-1, 0, 0]], dtype=float)
    si = scene.ray_intersect(origins, directions)
    np.testing.assert_allclose(si.t, [2.0 - 0.37, 2.0 - 0.6, 2.0 - 0.4, 2.0 - 0.2], rtol=1e-5)
    with pytest.raises(pr.PrismError, match="scene.plane.grid"):
        pr.load_dict({
            "type": "scene",
            "sensor": {"type": "perspective"},
            "plane": {"type": "sdfgrid", "grid": grid[..., 0]},
        })
