"""traverse and update: Mitsuba's keys, a changed scene rendering exactly as the edited scene
loaded from scratch, no mesh file read again, and clear errors."""

import shutil
from pathlib import Path
from typing import Any, Callable, Dict

import numpy as np
import pytest

import prism_renderer as pr
from conftest import ROOT, SIZE

T = pr.Transform


def small_cornell_box() -> Dict[str, Any]:
    """Mitsuba's Cornell box dictionary, small enough to render in a moment."""
    scene = pr.cornell_box()
    scene["sensor"]["film"]["width"] = SIZE["resx"]
    scene["sensor"]["film"]["height"] = SIZE["resy"]
    scene["sensor"]["sampler"]["sample_count"] = SIZE["spp"]
    return scene


def render(scene: pr.Scene) -> pr.Image:
    return pr.render(scene, seed=3, progress=False)


def assert_same_image(a: pr.Image, b: pr.Image) -> None:
    for name in ("rgb", "variance"):
        assert np.array_equal(getattr(a, name), getattr(b, name)), name


def test_the_keys_are_mitsubas():
    params = pr.traverse(pr.load_dict(small_cornell_box()))
    for key in (
        "sensor.to_world",
        "sensor.x_fov",
        "red.reflectance.value",
        "white.reflectance.value",
        "light.emitter.radiance.value",
        "light.to_world",
        "small-box.to_world",
    ):
        assert key in params, key
    assert list(params) == params.keys()
    assert len(params) == len(params.keys())
    assert isinstance(params["sensor.to_world"], pr.Transform)
    assert params["red.reflectance.value"].tolist() == [0.570068, 0.0430135, 0.0443706]
    # fov_axis "smaller": 39.3077° along y, on a film 1.2 times as wide as high.
    aspect = SIZE["resx"] / SIZE["resy"]
    x_fov = 2 * np.degrees(np.arctan(np.tan(np.radians(39.3077 / 2)) * aspect))
    assert params["sensor.x_fov"] == pytest.approx(x_fov, rel=1e-12)
    assert "red.reflectance.value" in repr(params)
    assert params["integrator.rr_depth"] == 5, "the path integrator's default"


def test_veach_mis_keys():
    params = pr.traverse(pr.load_file(ROOT / "scenes" / "veach-mis" / "scene.xml"))
    assert params["SmoothBSDF.brdf_0.alpha.value"] == 0.01
    assert params["Null_0001.emitter.radiance.value"].tolist() == [7.59909] * 3
    assert params["Null_0002.radius"] == 0.5
    assert params["sensor.x_fov"] == 35.0
    assert isinstance(params["Smooth.to_world"], pr.Transform)


def edit(scene: Dict[str, Any], path: str, value: Any) -> Dict[str, Any]:
    """The dictionary `scene` with the entry at `path` (dots between keys) set."""
    *parents, last = path.split(".")
    entry = scene
    for key in parents:
        entry = entry[key]
    entry[last] = value
    return scene


LOOK = T().look_at(origin=[0.1, 0.2, 3.8], target=[0.0, 0.1, 0.0], up=[0, 1, 0])

MOVED = T().translate([0.3, -0.7, 0.4]).rotate([0, 1, 0], -20).scale(0.3)
LAMP = T().translate([0.2, 0.99, 0.1]).rotate([1, 0, 0], 90).scale([0.3, 0.15, 0.15])

# (key, new value, its plugin, the entry of the dictionary it is written in, as written there):
# a colour, a camera's transform and field of view, an emitter's radiance, a shape's transform
# and an emitting shape's, and a parameter the scene leaves at its default.
CHANGES = [
    ("red.reflectance.value", [0.2, 0.5, 0.9], "red", "red.reflectance.value", [0.2, 0.5, 0.9]),
    ("sensor.to_world", LOOK, "sensor", "sensor.to_world", LOOK),
    ("sensor.x_fov", 30.5, "sensor", "sensor.fov", 30.5),
    (
        "light.emitter.radiance.value",
        np.array([9.0, 6.0, 2.5]),
        "light.emitter",
        "light.emitter.radiance.value",
        [9.0, 6.0, 2.5],
    ),
    ("small-box.to_world", MOVED, "small-box", "small-box.to_world", MOVED),
    ("light.to_world", LAMP, "light", "light.to_world", LAMP),
    ("integrator.rr_depth", 1, "integrator", "integrator.rr_depth", 1),
]


@pytest.mark.parametrize(
    "key, value, plugin, entry, written", CHANGES, ids=[c[0] for c in CHANGES]
)
def test_an_update_renders_as_the_edited_scene_from_scratch(key, value, plugin, entry, written):
    scene = pr.load_dict(small_cornell_box())
    before = render(scene)
    params = pr.traverse(scene)
    params[key] = value
    assert params.update() == [(plugin, {key})]
    edited = edit(small_cornell_box(), entry, written)
    if key == "sensor.x_fov":
        edited["sensor"]["fov_axis"] = "x"
    after = render(scene)
    assert_same_image(after, render(pr.load_dict(edited)))
    assert not np.array_equal(after.rgb, before.rgb), "the change shows in the image"


def test_a_dielectrics_eta_is_its_relative_index():
    def with_glass(**indices: float) -> Dict[str, Any]:
        scene = small_cornell_box()
        scene["large-box"]["bsdf"] = {"type": "dielectric", **indices}
        return scene

    scene = pr.load_dict(with_glass())
    before = render(scene)
    params = pr.traverse(scene)
    assert params["large-box.bsdf.eta"] == pytest.approx(1.5046 / 1.000277, rel=1e-6)
    params["large-box.bsdf.eta"] = 1.33
    params.update()
    assert params["large-box.bsdf.eta"] == 1.33
    after = render(scene)
    assert_same_image(after, render(pr.load_dict(with_glass(int_ior=1.33, ext_ior=1.0))))
    assert not np.array_equal(after.rgb, before.rgb)
    with pytest.raises(pr.PrismError, match="a positive number"):
        params["large-box.bsdf.eta"] = 0


def test_several_changes_and_update_with_values():
    scene = pr.load_dict(small_cornell_box())
    params = pr.traverse(scene)
    params["white.reflectance.value"] = 0.5
    updated = params.update({"sensor.to_world": LOOK, "green.reflectance.value": (0.1, 0.9, 0.1)})
    assert sorted(updated) == [
        ("green", {"green.reflectance.value"}),
        ("sensor", {"sensor.to_world"}),
        ("white", {"white.reflectance.value"}),
    ]
    assert params.update() == []
    edited = edit(small_cornell_box(), "white.reflectance.value", 0.5)
    edited = edit(edited, "sensor.to_world", LOOK)
    edited = edit(edited, "green.reflectance.value", [0.1, 0.9, 0.1])
    assert_same_image(render(scene), render(pr.load_dict(edited)))
    assert params["white.reflectance.value"].tolist() == [0.5, 0.5, 0.5]


def copy_cornell_box(folder: Path, replace: Callable[[str], str] = lambda text: text) -> Path:
    """The bundled Cornell box copied into `folder`, its XML text passed through `replace`."""
    source = ROOT / "scenes" / "cornell-box"
    shutil.copytree(source / "meshes", folder / "meshes")
    path = folder / "scene.xml"
    path.write_text(replace((source / "scene.xml").read_text()))
    return path


def test_no_mesh_file_is_read_again(tmp_path):
    """The meshes are deleted after loading; the updates still build the scene, and it renders
    as the edited file loaded from scratch."""
    filename = '<string name="filename" value="meshes/tall_block.obj"/>'
    luminaire = '<float name="reflectance" value="0.78"/>'

    def tall_block_at(x: float, reflectance: float) -> Callable[[str], str]:
        """The scene with the tall block moved by x and the luminaire's reflectance set."""
        moved = f'{filename}<transform name="to_world"><translate x="{x}"/></transform>'
        reflects = f'<float name="reflectance" value="{reflectance}"/>'
        return lambda text: text.replace(filename, moved).replace(luminaire, reflects)

    scene_path = copy_cornell_box(tmp_path / "loaded", tall_block_at(0, 0.78))
    scene = pr.load_file(scene_path, **SIZE)
    before = render(scene)
    shutil.rmtree(tmp_path / "loaded" / "meshes")
    params = pr.traverse(scene)
    params["shape_6.to_world"] = T().translate([-60, 0, 0])
    params["luminaire.reflectance.value"] = 0.25
    params.update()
    edited = copy_cornell_box(tmp_path / "edited", tall_block_at(-60, 0.25))
    after = render(scene)
    assert_same_image(after, render(pr.load_file(edited, **SIZE)))
    assert not np.array_equal(after.rgb, before.rgb)


def test_no_image_file_is_read_again(tmp_path):
    pixels = np.linspace(0.1, 0.9, 4 * 6 * 3, dtype=np.float32).reshape(4, 6, 3)
    pr.write_image(tmp_path / "texture.exr", pixels)
    scene_text = """<scene version="3.0.0">
        <sensor type="perspective">
            <float name="fov" value="{fov}"/>
            <transform name="to_world"><lookat origin="0, 0, 3" target="0, 0, 0" up="0, 1, 0"/></transform>
            <sampler type="independent"><integer name="sample_count" value="4"/></sampler>
            <film type="hdrfilm"><integer name="width" value="8"/><integer name="height" value="6"/></film>
        </sensor>
        <shape type="rectangle">
            <bsdf type="diffuse"><texture name="reflectance" type="bitmap"><string name="filename" value="texture.exr"/></texture></bsdf>
        </shape>
        <emitter type="constant"/>
    </scene>"""
    loaded = tmp_path / "loaded.xml"
    loaded.write_text(scene_text.format(fov=45))
    edited = tmp_path / "edited.xml"
    edited.write_text(scene_text.format(fov=30))
    reference = render(pr.load_file(edited))
    scene = pr.load_file(loaded)
    (tmp_path / "texture.exr").unlink()
    params = pr.traverse(scene)
    params["sensor.x_fov"] = 30
    params.update()
    assert_same_image(render(scene), reference)


def test_a_sampled_spectrum_keeps_its_wavelengths(cornell_path, tmp_path):
    scene = pr.load_file(cornell_path, **SIZE)
    params = pr.traverse(scene)
    values = params["red.reflectance.values"]
    assert values.shape == (76,)
    params["red.reflectance.values"] = values[::-1]
    params.update()
    text = cornell_path.read_text()
    start = text.index('<bsdf type="diffuse" id="red">')
    start = text.index('value="', start) + len('value="')
    end = text.index('"', start)
    pairs = [entry.split(":") for entry in text[start:end].split(",")]
    reversed_pairs = ", ".join(
        f"{wavelength.strip()}:{value.strip()}"
        for (wavelength, _), (_, value) in zip(pairs, reversed(pairs))
    )
    edited = copy_cornell_box(tmp_path, lambda t: t[:start] + reversed_pairs + t[end:])
    assert_same_image(render(scene), render(pr.load_file(edited, **SIZE)))
    with pytest.raises(pr.PrismError, match="76 finite numbers"):
        params["red.reflectance.values"] = values[:3]


def test_the_sensor_and_overrides_stay_after_an_update():
    scene = pr.load_dict(small_cornell_box())
    scene.wavelengths = "uniform"
    params = pr.traverse(scene)
    params["red.reflectance.value"] = 0.3
    params.update()
    assert scene.wavelengths == "uniform"
    reference = pr.load_dict(edit(small_cornell_box(), "red.reflectance.value", 0.3))
    reference.wavelengths = "uniform"
    assert_same_image(render(scene), render(reference))


def test_the_sensor_rendered_last_stays_seen_through():
    from test_sensors import SCENE

    scene = pr.load_string(SCENE)
    pr.render(scene, sensor="side", progress=False)
    params = pr.traverse(scene)
    assert params["side.film.width"] == 5
    params["shape_1.radius"] = 0.6
    params.update()
    assert (scene.sensor, scene.width, scene.height, scene.seed) == (1, 5, 3, 5)
    reference = pr.load_string(SCENE.replace('value="0.4"', 'value="0.6"'))
    assert_same_image(
        pr.render(scene, sensor="side", progress=False),
        pr.render(reference, sensor="side", progress=False),
    )


def test_an_unknown_key_names_the_closest():
    params = pr.traverse(pr.load_dict(small_cornell_box()))
    with pytest.raises(KeyError, match='did you mean "red.reflectance.value"'):
        params["red.reflectanse.value"]
    with pytest.raises(KeyError):
        params["nothing.like.it"] = 1.0


@pytest.mark.parametrize(
    "key, value, takes",
    [
        ("red.reflectance.value", [0.1, 0.2], "three finite numbers"),
        ("red.reflectance.value", "red", "three finite numbers"),
        ("red.reflectance.value", [0.1, float("nan"), 0.2], "three finite numbers"),
        ("sensor.to_world", [1, 2, 3], "a Transform or a 4 × 4 matrix"),
        ("sensor.x_fov", 190.0, "between 0 and 180"),
        ("sensor.x_fov", True, "between 0 and 180"),
        ("sensor.sampler.sample_count", 2.5, "an integer"),
    ],
)
def test_a_value_of_the_wrong_type_or_shape_is_refused(key, value, takes):
    params = pr.traverse(pr.load_dict(small_cornell_box()))
    with pytest.raises(pr.PrismError, match=takes):
        params[key] = value
    assert params.update() == []


def test_a_refused_update_leaves_the_scene_as_it_was():
    scene = pr.load_dict(small_cornell_box())
    before = render(scene)
    params = pr.traverse(scene)
    params["sensor.film.width"] = 0
    with pytest.raises(pr.PrismError):
        params.update()
    assert_same_image(render(scene), before)
    assert params["sensor.film.width"] == 0, "the change stays recorded"
    params["sensor.film.width"] = SIZE["resx"]
    params.update()
    assert_same_image(render(scene), before)


def test_keep_keeps_the_keys_its_patterns_match():
    params = pr.traverse(pr.load_dict(small_cornell_box()))
    params["white.reflectance.value"] = 0.5
    params["red.reflectance.value"] = 0.5
    params.keep([r".*\.reflectance\.value", "sensor.to_world"])
    assert sorted(params) == [
        "green.reflectance.value",
        "red.reflectance.value",
        "sensor.to_world",
        "white.reflectance.value",
    ]
    params.keep("red")
    assert params.keys() == ["red.reflectance.value"]
    assert params.update() == [("red", {"red.reflectance.value"})]
    with pytest.raises(KeyError, match='did you mean "red.reflectance.value"'):
        params.keep("red.reflectanse.value")


def test_a_scene_cannot_change_while_it_renders():
    scene = pr.load_dict(small_cornell_box())
    params = pr.traverse(scene)
    params["red.reflectance.value"] = 0.3

    def progress(samples: int, total: object, error: float) -> None:
        params.update()

    with pytest.raises(pr.PrismError, match="the scene is rendering"):
        pr.render(scene, progress=progress)
    assert params["red.reflectance.value"].tolist() == [0.3] * 3, "the change stays recorded"


def test_a_matrix_sets_a_transform():
    scene = pr.load_dict(small_cornell_box())
    params = pr.traverse(scene)
    params["sensor.to_world"] = LOOK.matrix
    params.update()
    assert params["sensor.to_world"] == LOOK


def test_a_moved_shape_refits_the_hierarchy():
    """Moving a shape refits the hierarchy built for the scene: the image is the edited scene's
    loaded from scratch up to noise (and rounding where a ray meets two surfaces at the very
    same distance); moved back, the refit tree is the built one, and the image is the
    original's bit for bit. A box grown to fill the room would make the tree too costly: the
    hierarchy is built again, as a load builds it."""
    scene = pr.load_dict(small_cornell_box())
    before = render(scene)
    assert not scene.bvh_refit
    params = pr.traverse(scene)
    original = params["small-box.to_world"]
    params["small-box.to_world"] = MOVED
    params.update()
    assert scene.bvh_refit
    moved = render(scene)
    assert not np.array_equal(moved.rgb, before.rgb)
    # Against the edited scene loaded and rendered with other random numbers, with enough
    # samples that the pixels' variance estimates hold.
    loaded = pr.load_dict(edit(small_cornell_box(), "small-box.to_world", MOVED))
    refit_image = pr.render(scene, spp=256, seed=3, progress=False)
    loaded_image = pr.render(loaded, spp=256, seed=4, progress=False)
    z_test = pr.compare(refit_image, loaded_image).z_test
    assert z_test is not None and z_test.consistent_with_noise, str(z_test)
    unmoved = pr.render(pr.load_dict(small_cornell_box()), spp=256, seed=4, progress=False)
    z_test = pr.compare(refit_image, unmoved).z_test
    assert z_test is not None and not z_test.consistent_with_noise, "the test sees the move"

    params["small-box.to_world"] = original
    params.update()
    assert scene.bvh_refit
    assert_same_image(render(scene), before)

    grown = T().scale(3) @ original
    params["small-box.to_world"] = grown
    params.update()
    assert not scene.bvh_refit
    edited = edit(small_cornell_box(), "small-box.to_world", grown)
    assert_same_image(render(scene), render(pr.load_dict(edited)))
