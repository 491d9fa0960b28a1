"""Mitsuba 3's names: its quickstart's calls run with ``import prism_renderer as mi``, and each
name behaves as Mitsuba's."""

from pathlib import Path

import numpy as np
import pytest

import prism_renderer as mi
from conftest import SIZE

T = mi.ScalarTransform4f


def test_mitsubas_quickstart_runs(tmp_path: Path, cornell_path: Path):
    # The calls of Mitsuba 3's quickstart tutorial and of its scene-format tutorial, with
    # fewer samples.
    assert "scalar_spectral" in mi.variants()
    mi.set_variant("scalar_spectral")
    assert mi.variant() == "scalar_spectral"

    scene = mi.load_file(cornell_path, **SIZE)
    image = mi.render(scene, spp=2, progress=False)
    # Mitsuba's `image ** (1.0 / 2.2)`; linear sRGB from spectra can be slightly negative.
    tonemapped = np.maximum(np.asarray(image), 0) ** (1.0 / 2.2)
    assert tonemapped.shape == (SIZE["resy"], SIZE["resx"], 3)
    assert np.all(np.isfinite(tonemapped))
    mi.util.write_bitmap(tmp_path / "my_first_render.png", image)
    mi.util.write_bitmap(tmp_path / "my_first_render.exr", image)
    assert np.array_equal(mi.read_image(tmp_path / "my_first_render.exr"), image.rgb)
    assert mi.read_image(tmp_path / "my_first_render.png").shape == image.rgb.shape

    scene = mi.load_dict(mi.cornell_box())
    assert (scene.width, scene.height, scene.spp) == (256, 256, 64)
    image = mi.render(scene, spp=1, progress=False)
    mi.util.write_bitmap(tmp_path / "cornell_box.png", image)
    assert (tmp_path / "cornell_box.png").stat().st_size > 0


# Mitsuba 3.9.1's scalar_spectral render of cornell_box() at 64 × 64 pixels: the image's mean
# R, G, B over 16 renders of 64 samples per pixel (seeds 1000 to 1015) and its standard error
# (the spread of the 16 means over √16).
MITSUBA_CORNELL_MEAN = np.array([0.234555, 0.140589, 0.058306])
MITSUBA_CORNELL_ERROR = np.array([0.000227, 0.000158, 0.000203])


def test_cornell_box_renders_as_mitsubas():
    scene_dict = mi.cornell_box()
    scene_dict["sensor"]["film"]["width"] = 64
    scene_dict["sensor"]["film"]["height"] = 64
    scene = mi.load_dict(scene_dict)
    means = np.array(
        [
            np.asarray(mi.render(scene, spp=64, seed=seed, progress=False)).reshape(-1, 3).mean(0)
            for seed in range(8)
        ]
    )
    error = means.std(axis=0, ddof=1) / np.sqrt(len(means))
    z = (means.mean(axis=0) - MITSUBA_CORNELL_MEAN) / np.hypot(error, MITSUBA_CORNELL_ERROR)
    assert np.all(np.abs(z) < 5), (means.mean(axis=0), error, z)


def test_rgb_and_mono_variants_are_refused_naming_the_spectral_model():
    for name in ("scalar_rgb", "llvm_ad_rgb", "scalar_mono", "cuda_ad_mono_polarized"):
        with pytest.raises(ImportError, match="Prism renders spectrally"):
            mi.set_variant(name)
    with pytest.raises(ImportError, match="does not track polarization"):
        mi.set_variant("scalar_spectral_polarized")
    with pytest.raises(ImportError, match="no such variant"):
        mi.set_variant("scalar_spectra")


def test_set_variant_takes_the_first_accepted_name():
    mi.set_variant("cuda_ad_rgb", "llvm_ad_spectral", "scalar_spectral")
    assert mi.variant() == "llvm_ad_spectral"
    mi.set_variant("scalar_spectral")
    assert set(mi.variants()) >= {"scalar_spectral", "llvm_ad_spectral", "cuda_ad_spectral"}


SCENE_TEXT = """<scene version="3.0.0">
    <default name="spp" value="4"/>
    <sensor type="perspective">
        <transform name="to_world"><lookat origin="0, 0, 4" target="0, 0, 0" up="0, 1, 0"/></transform>
        <sampler type="independent"><integer name="sample_count" value="$spp"/></sampler>
        <film type="hdrfilm"><integer name="width" value="16"/><integer name="height" value="12"/></film>
    </sensor>
    <shape type="sphere"><bsdf type="diffuse"/></shape>
    <emitter type="constant"/>
</scene>
"""


def test_load_string_is_load_file_of_the_same_text(tmp_path: Path):
    path = tmp_path / "scene.xml"
    path.write_text(SCENE_TEXT)
    from_string = mi.load_string(SCENE_TEXT, spp=2)
    from_file = mi.load_file(path, spp=2)
    assert (from_string.width, from_string.height, from_string.spp) == (16, 12, 2)
    a = mi.render(from_string, seed=3, progress=False)
    b = mi.render(from_file, seed=3, progress=False)
    assert np.array_equal(a.rgb, b.rgb)
    assert np.array_equal(a.variance, b.variance)


def test_load_string_errors_name_the_string_and_the_line():
    with pytest.raises(mi.PrismError) as caught:
        mi.load_string(SCENE_TEXT.replace('<bsdf type="diffuse"/>', '<bsdf type="difuse"/>'))
    assert caught.value.file == "<string>"
    assert caught.value.line == 8


def test_a_transform_applies_to_points_as_mitsubas():
    t = T().translate([1, 2, 3]).rotate([0, 0, 1], 90).scale(2)
    point = t @ [1, 0, 0]
    assert isinstance(point, np.ndarray) and point.shape == (3,)
    assert np.allclose(point, [1, 4, 3])
    points = t @ np.array([[1, 0, 0], [0, 0, 1], [0, 0, 0]])
    assert points.shape == (3, 3)
    assert np.allclose(points, [[1, 4, 3], [1, 2, 5], [1, 2, 3]])
    assert isinstance(t @ T().scale(3), mi.Transform)
    assert np.allclose((t @ T().scale(3)) @ [1, 0, 0], t @ [3, 0, 0])


def test_points_are_divided_by_w():
    projective = np.eye(4)
    projective[3] = [0, 0, 1, 0]  # w = z
    assert np.allclose(T(projective) @ [2, 4, 2], [1, 2, 1])


def test_write_bitmap_writes_arrays(tmp_path: Path):
    values = np.random.default_rng(1).random((5, 7, 3), dtype=np.float32)
    mi.util.write_bitmap(str(tmp_path / "values.exr"), values, write_async=False)
    assert np.array_equal(mi.read_image(tmp_path / "values.exr"), values)
    mi.util.write_bitmap(tmp_path / "values.png", values)
    assert np.allclose(mi.read_image(tmp_path / "values.png"), values, atol=0.01)
