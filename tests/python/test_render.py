"""Rendering: the same arrays as the command line's EXR, for any number of threads; the
stopping rules; progress reports."""

import math
import subprocess
import sys

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


def test_without_tqdm_progress_is_a_line_on_stderr(cornell, monkeypatch, capsys):
    monkeypatch.setitem(sys.modules, "tqdm.auto", None)
    pr.render(cornell, progress=True)
    err = capsys.readouterr().err
    total = SIZE["spp"] * SIZE["resx"] * SIZE["resy"]
    assert f"prism: 100.0 % of {total} samples" in err
    assert err.endswith("\n")
