"""``denoise``: Open Image Denoise through pyoidn lowers a noisy render's error and checks its
inputs."""

import sys

import numpy as np
import pytest

import prism_renderer as pr


def relative_mse(image: np.ndarray, reference: np.ndarray) -> float:
    """Mean of (x − r)² / (r² + 10⁻²), as `prism compare` computes relMSE."""
    return float(np.mean((image - reference) ** 2 / (reference**2 + 1e-2)))


def test_denoising_lowers_a_noisy_renders_error(cornell_path):
    noisy = pr.render(pr.load_file(cornell_path, spp=4, resx=64, resy=64), seed=1, progress=False)
    reference = pr.render(
        pr.load_file(cornell_path, spp=256, resx=64, resy=64), seed=2, progress=False
    ).rgb
    noisy_rgb = noisy.rgb.copy()
    denoised = pr.denoise(noisy)
    assert denoised.shape == (64, 64, 3) and denoised.dtype == np.float32
    # The image itself is left as it was.
    assert np.array_equal(noisy.rgb, noisy_rgb)
    before, after = relative_mse(noisy.rgb, reference), relative_mse(denoised, reference)
    # Measured: 4-spp relMSE about 0.09, denoised about 0.015 (6×).
    assert after < before / 3, (before, after)
    # Arrays work as the image does, and guides of the right shape are accepted.
    assert np.array_equal(pr.denoise(np.asarray(noisy)), denoised)
    flat = np.full((64, 64, 3), 0.5, np.float32)
    assert pr.denoise(noisy, albedo=flat).shape == (64, 64, 3)


def test_bad_inputs_are_refused_with_a_reason():
    image = np.zeros((8, 8, 3), np.float32)
    with pytest.raises(ValueError, match="H x W x 3"):
        pr.denoise(np.zeros((8, 8), np.float32))
    with pytest.raises(ValueError, match="albedo has shape"):
        pr.denoise(image, albedo=np.zeros((4, 4, 3), np.float32))
    with pytest.raises(ValueError, match="needs an albedo"):
        pr.denoise(image, normal=image)


def test_without_pyoidn_the_error_says_what_to_install(monkeypatch):
    monkeypatch.setitem(sys.modules, "pyoidn", None)
    with pytest.raises(ImportError, match=r"prism-renderer\[denoise\]"):
        pr.denoise(np.zeros((8, 8, 3), np.float32))
