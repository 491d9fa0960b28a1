"""Scenes with several sensors: ``render(scene, sensor=...)`` by index or id looks through the
chosen one, as Mitsuba's ``mi.render(scene, sensor=...)``, with the same image as
``prism render --sensor``; the default is the first sensor."""

import subprocess

import numpy as np
import pytest

import prism_renderer as pr
from test_load import assert_same_image

# Box filters, as in the Cornell box that the other tests compare with the command line.
SCENE = """<scene version="3.0.0">
    <sensor type="perspective">
        <transform name="to_world"><lookat origin="0, 0, 4" target="0, 0, 0" up="0, 1, 0"/></transform>
        <sampler type="independent"><integer name="sample_count" value="4"/></sampler>
        <film type="hdrfilm"><integer name="width" value="6"/><integer name="height" value="4"/><rfilter type="box"/></film>
    </sensor>
    <sensor type="perspective" id="side">
        <transform name="to_world"><lookat origin="3, 1, 3" target="0, 0, 0" up="0, 1, 0"/></transform>
        <sampler type="independent"><integer name="sample_count" value="4"/><integer name="seed" value="5"/></sampler>
        <film type="hdrfilm"><integer name="width" value="5"/><integer name="height" value="3"/><rfilter type="box"/></film>
    </sensor>
    <shape type="rectangle"><emitter type="area"/></shape>
    <shape type="sphere"><float name="radius" value="0.4"/></shape>
    <emitter type="constant"><rgb name="radiance" value="0.5"/></emitter>
</scene>
"""


@pytest.fixture()
def two_sensors(tmp_path):
    path = tmp_path / "sensors.xml"
    path.write_text(SCENE)
    return path


def test_the_first_sensor_is_the_default(two_sensors):
    scene = pr.load_file(two_sensors)
    assert scene.sensor_ids == [None, "side"]
    assert scene.sensor == 0
    assert (scene.width, scene.height) == (6, 4)
    assert pr.render(scene, progress=False).xyz.shape == (4, 6, 3)


def test_a_sensor_by_index_or_id_renders_as_the_command_line(two_sensors, prism_cli, tmp_path):
    exr = tmp_path / "side.exr"
    subprocess.run(
        [str(prism_cli), "render", str(two_sensors), "--sensor", "side", "-o", str(exr)],
        check=True,
        capture_output=True,
    )
    scene = pr.load_file(two_sensors)
    by_id = pr.render(scene, sensor="side", progress=False)
    assert scene.sensor == 1
    assert (scene.width, scene.height, scene.seed) == (5, 3, 5)
    assert_same_image(by_id, pr.Image.read(exr))
    assert_same_image(by_id, pr.render(scene, sensor=1, progress=False))
    first = pr.render(scene, progress=False)
    assert scene.sensor == 0
    assert first.xyz.shape == (4, 6, 3)
    assert not np.array_equal(first.xyz[:3, :5], by_id.xyz)


def test_a_sensor_that_does_not_exist_raises(two_sensors):
    scene = pr.load_file(two_sensors)
    with pytest.raises(pr.PrismError, match='no sensor "front"'):
        pr.render(scene, sensor="front", progress=False)
    with pytest.raises(pr.PrismError, match="no sensor 2"):
        pr.render(scene, sensor=2, progress=False)
    assert scene.sensor == 0
