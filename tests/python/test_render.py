"""Rendering: the same arrays as the command line's EXR, for any number of threads; the
stopping rules; progress reports; the preview of the developing image."""

import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import prism_renderer as pr
from conftest import SIZE
from test_load import assert_same_image


def test_the_arrays_equal_the_command_lines_exr(cornell_path, prism_cli, tmp_path):
    exr = tmp_path / "cli.exr"
    subprocess.run(
        [
            str(prism_cli),
            "render",
            str(cornell_path),
            "-o",
            str(exr),
            "--spp",
            "3",
            "--seed",
            "7",
            "-D",
            f"resx={SIZE['resx']}",
            "-D",
            f"resy={SIZE['resy']}",
        ],
        check=True,
        capture_output=True,
    )
    scene = pr.load_file(cornell_path, resx=SIZE["resx"], resy=SIZE["resy"])
    image = pr.render(scene, spp=3, seed=7, progress=False)
    assert image.spp == 3
    assert_same_image(image, pr.Image.read(exr))
    other_seed = pr.render(scene, spp=3, seed=8, progress=False)
    assert not np.array_equal(image.xyz, other_seed.xyz)


def test_the_image_does_not_depend_on_the_number_of_threads(cornell):
    one = pr.render(cornell, seed=2, threads=1, progress=False)
    three = pr.render(cornell, seed=2, threads=3, progress=False)
    assert_same_image(one, three)


def test_the_seed_defaults_to_the_samplers(cornell):
    assert cornell.seed == 0
    assert_same_image(
        pr.render(cornell, progress=False), pr.render(cornell, seed=0, progress=False)
    )


def test_progress_reports_reach_the_total(cornell):
    reports = []
    pr.render(cornell, progress=lambda *report: reports.append(report), spp=6)
    pixels = SIZE["resx"] * SIZE["resy"]
    samples, total, error = reports[-1]
    assert total == 6 * pixels
    assert samples == total
    assert 0 < error < math.inf
    assert all(r[0] <= total for r in reports)


def test_the_default_progress_bar_runs(cornell, capsys):
    image = pr.render(cornell, progress=True)
    assert image.spp == SIZE["spp"]


def test_a_time_limit_stops_an_open_ended_render(cornell):
    image = pr.render(cornell, time_limit=0.3, progress=False)
    assert image.spp >= 1
    assert image.seconds < 30


def test_a_target_error_stops_the_render(cornell):
    image = pr.render(cornell, target_error=0.5, spp=10_000, progress=False)
    assert 1 <= image.spp < 10_000
    assert np.nanmean(image.relative_error) > 0


@pytest.mark.parametrize(
    "arguments, words",
    [
        ({"spp": 0}, "spp must be at least 1"),
        ({"threads": 0}, "threads must be at least 1"),
        ({"time_limit": -1.0}, "time_limit must be a positive number"),
        ({"target_error": 0.0}, "target_error must be positive"),
    ],
)
def test_bad_arguments_raise(cornell, arguments, words):
    with pytest.raises(pr.PrismError, match=words):
        pr.render(cornell, progress=False, **arguments)


def test_an_exception_in_the_progress_callback_stops_the_render(cornell):
    def fail(samples, total, error):
        raise ValueError("stop here")

    with pytest.raises(ValueError, match="stop here"):
        pr.render(cornell, time_limit=60, progress=fail)


def test_the_preview_sees_the_image_develop_and_last_the_result(cornell):
    images = []
    image = pr.render(cornell, spp=64, progress=False, preview=images.append)
    assert_same_image(images[-1], image)
    reference = pr.render(cornell, spp=64, progress=False)
    assert_same_image(images[-1], reference)
    spps = [shown.spp for shown in images]
    assert spps == sorted(set(spps)) and spps[-1] == 64
    for shown in images[:-1]:
        assert 1 <= shown.spp < 64 and shown.rgb.shape == image.rgb.shape
        assert not np.array_equal(shown.rgb, image.rgb)


def test_an_exception_in_the_preview_stops_the_render(cornell):
    def fail(image):
        raise ValueError("seen enough")

    with pytest.raises(ValueError, match="seen enough"):
        pr.render(cornell, time_limit=60, progress=False, preview=fail)


def test_without_tqdm_progress_is_a_line_on_stderr(cornell, monkeypatch, capsys):
    monkeypatch.setitem(sys.modules, "tqdm.auto", None)
    pr.render(cornell, progress=True)
    err = capsys.readouterr().err
    total = SIZE["spp"] * SIZE["resx"] * SIZE["resy"]
    assert f"prism: 100.0 % of {total} samples" in err
    assert err.endswith("\n")


def test_the_wavelength_density_is_the_command_lines_option(cornell_path, prism_cli, tmp_path):
    exr = tmp_path / "visible.exr"
    size = [f"resx={SIZE['resx']}", f"resy={SIZE['resy']}"]
    subprocess.run(
        [str(prism_cli), "render", str(cornell_path), "-o", str(exr), "--spp", "3"]
        + ["--seed", "7", "--wavelengths", "balanced", "-D", size[0], "-D", size[1]],
        check=True,
        capture_output=True,
    )
    scene = pr.load_file(cornell_path, resx=SIZE["resx"], resy=SIZE["resy"])
    assert scene.wavelengths == "visible"
    default = pr.render(scene, spp=3, seed=7, progress=False)
    scene.wavelengths = "balanced"
    assert scene.wavelengths == "balanced"
    balanced = pr.render(scene, spp=3, seed=7, progress=False)
    assert_same_image(balanced, pr.Image.read(exr))
    assert not np.array_equal(default.xyz, balanced.xyz)


def test_an_unknown_wavelength_density_is_an_error(cornell_path):
    scene = pr.load_file(cornell_path, resx=SIZE["resx"], resy=SIZE["resy"])
    with pytest.raises(pr.PrismError) as raised:
        scene.wavelengths = "visibel"
    assert "visibel" in raised.value.message
    assert "visible" in (raised.value.help or "")
    assert scene.wavelengths == "visible"


def test_the_reconstruction_is_the_command_lines_option(prism_cli, tmp_path):
    bar = Path(__file__).resolve().parents[2] / "scenes" / "filters" / "mitchell-bar.xml"
    assert bar.is_file(), f"{bar} is missing"
    exr = tmp_path / "pixel.exr"
    subprocess.run(
        [str(prism_cli), "render", str(bar), "-o", str(exr), "--spp", "3", "--seed", "7"]
        + ["--reconstruction", "pixel", "-D", "resx=16", "-D", "resy=12"],
        check=True,
        capture_output=True,
    )
    scene = pr.load_file(bar, resx=16, resy=12)
    assert scene.reconstruction == "filter_mis"
    shared = pr.render(scene, spp=3, seed=7, progress=False)
    scene.reconstruction = "pixel"
    assert scene.reconstruction == "pixel"
    pixel = pr.render(scene, spp=3, seed=7, progress=False)
    assert_same_image(pixel, pr.Image.read(exr))
    assert not np.array_equal(shared.xyz, pixel.xyz)
    with pytest.raises(pr.PrismError) as raised:
        scene.reconstruction = "splat"
    assert "splat" in raised.value.message
    assert "filter_mis" in (raised.value.help or "")


AOV_INTEGRATOR = """<integrator type="aov">
        <string name="aovs" value="dd.y:depth,nn:sh_normal"/>
        <integrator type="path" name="image"/>
    </integrator>"""


@pytest.fixture(scope="module")
def aov_scene_path(cornell_path, tmp_path_factory):
    """The Cornell box with the aov integrator around its path tracer, beside its meshes."""
    text = cornell_path.read_text()
    start = text.index('<integrator type="path">')
    end = text.index("</integrator>", start) + len("</integrator>")
    written = text[:start] + AOV_INTEGRATOR + text[end:]
    directory = tmp_path_factory.mktemp("aov")
    for entry in cornell_path.parent.iterdir():
        if entry.name != cornell_path.name:
            (directory / entry.name).symlink_to(entry)
    path = directory / "scene.xml"
    path.write_text(written)
    return path


def test_aov_channels_are_arrays_named_as_in_the_exr(aov_scene_path, prism_cli, tmp_path):
    exr = tmp_path / "aov.exr"
    size = [f"resx={SIZE['resx']}", f"resy={SIZE['resy']}"]
    subprocess.run(
        [str(prism_cli), "render", str(aov_scene_path), "-o", str(exr), "--spp", "2"]
        + ["--seed", "3", "-D", size[0], "-D", size[1]],
        check=True,
        capture_output=True,
    )
    scene = pr.load_file(aov_scene_path, resx=SIZE["resx"], resy=SIZE["resy"])
    image = pr.render(scene, spp=2, seed=3, progress=False)
    names = ["dd.y.T", "nn.X", "nn.Y", "nn.Z"] + [f"image.{c}" for c in "RGBA"]
    assert sorted(image.aovs) == sorted(names)
    for name in names:
        assert image.aovs[name].shape == (SIZE["resy"], SIZE["resx"])
        assert image.aovs[name].dtype == np.float32
    assert (image.aovs["dd.y.T"] >= 0).all() and (image.aovs["dd.y.T"] > 0).mean() > 0.5
    from_cli = pr.Image.read(exr)
    assert_same_image(image, from_cli)
    for name in names:
        assert np.array_equal(image.aovs[name], from_cli.aovs[name]), name
    written = tmp_path / "written.exr"
    image.aovs["dd.y.T"][0, 0] = -1.0
    image.write(written)
    assert pr.Image.read(written).aovs["dd.y.T"][0, 0] == -1.0


def test_an_aov_that_is_no_longer_an_image_is_an_error(aov_scene_path, tmp_path):
    scene = pr.load_file(aov_scene_path, resx=SIZE["resx"], resy=SIZE["resy"])
    image = pr.render(scene, spp=1, progress=False)
    image.aovs["dd.y.T"] = np.zeros((2, 2), dtype=np.float32)
    with pytest.raises(pr.PrismError) as raised:
        image.write(tmp_path / "bad.exr")
    assert "dd.y.T" in raised.value.message


def _cli_render(prism_cli, cornell_path, exr, *arguments):
    subprocess.run(
        [str(prism_cli), "render", str(cornell_path), "-o", str(exr), "--seed", "7", "-q",
         "-D", f"resx={SIZE['resx']}", "-D", f"resy={SIZE['resy']}", *arguments],
        check=True,
        capture_output=True,
    )
    return pr.Image.read(exr)


def test_a_crop_renders_the_command_lines_crop(cornell_path, prism_cli, tmp_path):
    scene = pr.load_file(cornell_path, resx=SIZE["resx"], resy=SIZE["resy"])
    cropped = pr.render(scene, spp=3, seed=7, crop=(4, 3, 15, 12), progress=False)
    assert (cropped.width, cropped.height) == (11, 9)
    cli = _cli_render(prism_cli, cornell_path, tmp_path / "crop.exr", "--spp", "3",
                      "--crop", "4,3,15,12")
    assert_same_image(cropped, cli)
    # The scene keeps its whole film, whose pixels in the window are the crop's.
    whole = pr.render(scene, spp=3, seed=7, progress=False)
    assert whole.rgb.shape[:2] == (SIZE["resy"], SIZE["resx"])
    assert np.array_equal(whole.xyz[3:12, 4:15], cropped.xyz)
    with pytest.raises(pr.PrismError, match="outside"):
        pr.render(scene, crop=(0, 0, SIZE["resx"] + 1, 2), progress=False)


def test_checkpoints_and_resuming_are_the_command_lines(cornell_path, prism_cli, tmp_path):
    scene = pr.load_file(cornell_path, resx=SIZE["resx"], resy=SIZE["resy"])
    whole = pr.render(scene, spp=5, seed=7, progress=False)
    # Python's state is the command line's, byte for byte.
    python_state, cli_state = tmp_path / "python.state", tmp_path / "cli.state"
    checkpointed = pr.render(scene, spp=5, seed=7, checkpoint=python_state, progress=False)
    assert_same_image(checkpointed, whole)
    _cli_render(prism_cli, cornell_path, tmp_path / "a.exr", "--spp", "5",
                "--checkpoint", str(cli_state))
    assert python_state.read_bytes() == cli_state.read_bytes()
    # Python continues the command line's partial render (samples 0..2 of 5) to the image of
    # one render, writing the state back to the file it resumed.
    part = tmp_path / "part.state"
    _cli_render(prism_cli, cornell_path, tmp_path / "b.exr", "--spp", "5",
                "--sample-range", "0..2", "--checkpoint", str(part))
    resumed = pr.render(scene, spp=5, seed=7, resume=part, progress=False)
    assert resumed.spp == 5
    assert_same_image(resumed, whole)
    assert part.read_bytes() == cli_state.read_bytes()
    with pytest.raises(pr.PrismError, match="nothing to render"):
        pr.render(scene, spp=5, seed=7, resume=part, progress=False)
    with pytest.raises(pr.PrismError, match="seed"):
        pr.render(scene, spp=5, seed=8, resume=part, progress=False)
