"""The image object: files, the notebook's PNG, comparisons."""

import subprocess

import numpy as np
import pytest

import prism_renderer as pr
from test_load import assert_same_image


@pytest.fixture(scope="module")
def image(cornell) -> pr.Image:
    return pr.render(cornell, seed=3, progress=False)


def test_an_exr_reads_back_as_the_same_arrays(image, tmp_path):
    path = tmp_path / "out.exr"
    image.write(path)
    assert_same_image(image, pr.Image.read(str(path)))


def test_png_files_and_the_notebook_view_are_the_same_png(image, tmp_path):
    path = tmp_path / "out.png"
    image.write(path)
    data = image._repr_png_()
    assert data.startswith(b"\x89PNG\r\n\x1a\n")
    assert path.read_bytes() == data


def test_the_arrays_are_writable_and_write_uses_them(image, tmp_path):
    copy = pr.Image.read(_written(image, tmp_path / "a.exr"))
    copy.rgb[...] = 0.5
    again = pr.Image.read(_written(copy, tmp_path / "b.exr"))
    assert np.all(again.rgb == 0.5)
    assert np.array_equal(again.xyz, image.xyz)


def _written(image, path):
    image.write(path)
    return path


def test_an_unknown_extension_is_an_error(image, tmp_path):
    with pytest.raises(pr.PrismError, match=r"\.exr or \.png"):
        image.write(tmp_path / "out.jpg")


def test_reading_a_missing_exr_is_an_error(tmp_path):
    with pytest.raises(pr.PrismError):
        pr.Image.read(tmp_path / "missing.exr")


def test_an_image_equals_itself(image):
    comparison = pr.compare(image, image)
    assert comparison.rel_mse == 0
    assert [c.name for c in comparison.channels] == ["R", "G", "B"]
    assert comparison.z_test is not None and comparison.z_test.consistent_with_noise


def test_compare_gives_the_command_lines_statistics(cornell, prism_cli, tmp_path):
    a = _written(pr.render(cornell, seed=1, progress=False), tmp_path / "a.exr")
    b = _written(pr.render(cornell, seed=2, progress=False), tmp_path / "b.exr")
    printed = subprocess.run(
        [str(prism_cli), "compare", str(a), str(b), "--diff", str(tmp_path / "cli-diff.png")],
        check=True,
        capture_output=True,
        text=True,
    ).stdout
    comparison = pr.compare(a, pr.Image.read(b), diff=tmp_path / "diff.png")
    assert str(comparison) in printed
    assert (tmp_path / "diff.png").read_bytes() == (tmp_path / "cli-diff.png").read_bytes()
    assert comparison.rel_mse > 0
    z = comparison.z_test
    assert z.pixels > 0 and 0 <= z.p_value <= 1
    assert pr.compare(a, b, channels=["Y"]).channels[0].name == "Y"


def test_images_of_different_sizes_do_not_compare(image, cornell_path):
    small = pr.render(pr.load_file(cornell_path, spp=1, resx=4, resy=4), progress=False)
    with pytest.raises(pr.PrismError, match="same resolution"):
        pr.compare(image, small)
