"""Images as numpy arrays: ``np.asarray(image)``, ``write_image`` and ``read_image`` round
trips, Mitsuba's EXR files, and the EXR variants ``prism render`` writes."""

import struct
import subprocess
from pathlib import Path

import numpy as np
import pytest

import prism_renderer as pr
from conftest import SIZE

DATA = Path(__file__).resolve().parents[1] / "data"


@pytest.fixture(scope="module")
def image(cornell) -> pr.Image:
    return pr.render(cornell, seed=3, progress=False)


def _random(shape, seed=1):
    return np.random.default_rng(seed).uniform(0.0, 4.0, shape).astype(np.float32)


def _srgb_encode(linear):
    v = np.clip(linear, 0.0, 1.0).astype(np.float64)
    return np.where(v <= 0.0031308, 12.92 * v, 1.055 * v ** (1 / 2.4) - 0.055)


def test_an_image_is_an_array_equal_to_its_rgb(image):
    array = np.asarray(image)
    assert array.shape == (SIZE["resy"], SIZE["resx"], 3)
    assert array.dtype == np.float32
    assert np.array_equal(array, image.rgb)
    assert np.asarray(image, dtype=np.float64).dtype == np.float64
    copy = np.array(image, copy=True)
    copy[...] = -1.0
    assert not np.any(image.rgb == -1.0)


@pytest.mark.parametrize("shape", [(5, 7), (5, 7, 1), (5, 7, 2), (5, 7, 3), (5, 7, 4)])
def test_exr_round_trips_bit_for_bit(tmp_path, shape):
    array = _random(shape)
    path = tmp_path / "a.exr"
    pr.write_image(path, array)
    back = pr.read_image(path)
    assert back.dtype == np.float32
    assert np.array_equal(back, array.reshape(back.shape))
    assert back.shape == (shape if len(shape) == 2 or shape[2] > 1 else shape[:2])


def test_exr_channels_are_named_and_read_by_name(tmp_path):
    array = _random((4, 6, 5), seed=2)
    names = ["albedo.R", "albedo.G", "albedo.B", "depth", "mask"]
    path = tmp_path / "named.exr"
    pr.write_image(path, array, channels=names)
    for c, name in enumerate(names):
        assert np.array_equal(pr.read_image(path, channels=[name]), array[..., c])
    # No standard set: every channel, in the file's alphabetical order.
    order = sorted(range(5), key=lambda c: names[c])
    assert np.array_equal(pr.read_image(path), array[..., order])
    with pytest.raises(pr.PrismError, match="no channel \"R\""):
        pr.read_image(path, channels=["R"])
    with pytest.raises(pr.PrismError, match="name the 5 channels"):
        pr.write_image(tmp_path / "unnamed.exr", array)


def test_a_float16_array_is_written_as_half_floats(tmp_path):
    array = _random((3, 4, 3), seed=3).astype(np.float16)
    half, full = tmp_path / "half.exr", tmp_path / "full.exr"
    pr.write_image(half, array)
    pr.write_image(full, array.astype(np.float32))
    assert np.array_equal(pr.read_image(half), array.astype(np.float32))
    assert half.stat().st_size < full.stat().st_size


@pytest.mark.parametrize("extension", ["png", "jpg"])
@pytest.mark.parametrize("channels", [1, 2, 3, 4])
def test_8_bit_files_round_trip_within_their_quantisation(tmp_path, extension, channels):
    if extension == "jpg" and channels in (2, 4):
        with pytest.raises(pr.PrismError):
            pr.write_image(tmp_path / "a.jpg", _random((6, 8, channels)) / 4.0)
        return
    array = _random((6, 8, channels), seed=channels) / 4.0
    path = tmp_path / f"a.{extension}"
    pr.write_image(path, array)
    back = pr.read_image(path)
    if channels == 2:  # grey with alpha reads as RGBA
        back = back[..., [0, 3]]
    back = back.reshape(array.shape)
    alpha = channels in (2, 4)
    colour = array[..., :-1] if alpha else array
    back_colour = back[..., :-1] if alpha else back
    # PNG rounds each value to 8 bits; baseline JPEG of quality 100 also quantises its
    # frequencies and, in colour, subsamples and converts to YCbCr.
    tolerance = 0.5 / 255 + 1e-6 if extension == "png" else 12 / 255
    assert np.max(np.abs(_srgb_encode(back_colour) - _srgb_encode(colour))) <= tolerance
    if alpha:
        assert np.max(np.abs(back[..., -1] - array[..., -1])) <= 0.5 / 255 + 1e-6


def test_a_radiance_hdr_file_reads_as_linear_values(tmp_path):
    # A flat (uncompressed) RGBE file of 2 x 3 pixels: each value is mantissa / 256 * 2^(e - 128).
    pixels = [(128, 64, 32, 129), (255, 0, 0, 128), (1, 2, 3, 120),
              (200, 100, 50, 130), (0, 0, 0, 0), (128, 128, 128, 128)]
    header = b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 2 +X 3\n"
    path = tmp_path / "a.hdr"
    path.write_bytes(header + b"".join(struct.pack("4B", *p) for p in pixels))
    expected = np.array(
        [[m * 2.0 ** (e - 136) if e else 0.0 for m in p[:3]] for p, e in ((p, p[3]) for p in pixels)],
        dtype=np.float32,
    ).reshape(2, 3, 3)
    back = pr.read_image(path)
    assert back.shape == (2, 3, 3)
    assert np.allclose(back, expected, rtol=1e-6, atol=0.0)


def test_mitsubas_exr_files_read_as_mitsuba_reads_them():
    # Mitsuba 3.9.1's own numbers for these files (tests/data/README.md).
    rgba = pr.read_image(DATA / "mitsuba-rgba-float16.exr")
    assert rgba.shape == (12, 16, 4)
    assert np.allclose(
        rgba.mean(axis=(0, 1), dtype=np.float64),
        [0.02074131028105815, 0.05154002271592617, 0.0839121335496505, 0.38671875],
        rtol=1e-12,
    )
    assert rgba[6, 8].tolist() == [0.0716552734375, 0.169677734375, 0.317626953125, 1.0]
    luminance = pr.read_image(DATA / "mitsuba-luminance-float32.exr")
    assert luminance.shape == (12, 16)
    assert luminance.mean(dtype=np.float64) == pytest.approx(0.047326439121434305, rel=1e-12)
    assert luminance[6, 8] == np.float32(0.15952563285827637)


def test_a_missing_or_unknown_file_is_an_error(tmp_path):
    with pytest.raises(pr.PrismError, match="missing.exr"):
        pr.read_image(tmp_path / "missing.exr")
    with pytest.raises(pr.PrismError, match=r"\.exr, \.png"):
        pr.write_image(tmp_path / "a.tiff", np.zeros((2, 2, 3), np.float32))
    with pytest.raises(pr.PrismError, match="H × W"):
        pr.write_image(tmp_path / "a.exr", np.zeros(4, np.float32))


def _render_cli(prism_cli, scene, exr, *arguments):
    subprocess.run(
        [str(prism_cli), "render", str(scene), "-o", str(exr), "--spp", "4", "--seed", "5",
         "-D", f"resx={SIZE['resx']}", "-D", f"resy={SIZE['resy']}", *arguments],
        check=True,
        capture_output=True,
    )


def test_a_half_render_reads_as_the_rounded_image(cornell_path, prism_cli, tmp_path):
    full, half = tmp_path / "full.exr", tmp_path / "half.exr"
    _render_cli(prism_cli, cornell_path, full)
    _render_cli(prism_cli, cornell_path, half, "--half")
    a, b = pr.Image.read(full), pr.Image.read(half)
    assert np.array_equal(b.rgb, a.rgb.astype(np.float16).astype(np.float32))
    assert np.array_equal(b.variance, a.variance)
    assert (b.spp, b.seed) == (4, 5) and b.seconds > 0
    assert np.array_equal(pr.read_image(half), b.rgb)
    assert half.stat().st_size < full.stat().st_size
