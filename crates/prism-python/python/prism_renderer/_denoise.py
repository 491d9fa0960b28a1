"""``denoise``: Intel Open Image Denoise on a rendered image, through the ``pyoidn`` package."""

from __future__ import annotations

from typing import Any, Optional

import numpy as np
import numpy.typing as npt


def denoise(
    image: Any,
    albedo: Optional[npt.ArrayLike] = None,
    normal: Optional[npt.ArrayLike] = None,
) -> npt.NDArray[np.float32]:
    """The image denoised by Open Image Denoise's ``RT`` filter for HDR images, as
    ``prism render --denoise`` does: ``image`` is an :class:`Image` (its ``rgb``) or an
    H x W x 3 array of linear values; ``albedo`` and ``normal`` (H x W x 3, optional, both or
    albedo alone) guide it: the first hit's albedo and shading normal, as an ``aov``
    integrator's ``albedo`` and ``sh_normal`` variables give them. Returns a new H x W x 3 float32
    array; the image is not changed (its variance and error bars stay those of the noisy
    estimate).

    Needs the optional dependency ``pyoidn`` (``pip install "prism-renderer[denoise]"``), which
    ships the library for x86-64 Linux; without it this raises ``ImportError`` saying so.
    """
    try:
        import pyoidn
    except ImportError as error:
        raise ImportError(
            "denoise needs the pyoidn package (Intel Open Image Denoise): "
            'pip install "prism-renderer[denoise]"'
        ) from error
    color = _rgb(image, "image")
    guides = {}
    if albedo is not None:
        guides["albedo"] = _rgb(albedo, "albedo", color.shape)
    if normal is not None:
        if albedo is None:
            raise ValueError("a normal guide needs an albedo guide too (as Open Image Denoise does)")
        guides["normal"] = _rgb(normal, "normal", color.shape)
    result = pyoidn.denoise(color, hdr=True, **guides)
    return np.asarray(result, dtype=np.float32)


def _rgb(value: Any, name: str, shape: Optional[tuple] = None) -> npt.NDArray[np.float32]:
    array = np.ascontiguousarray(np.asarray(value), dtype=np.float32)
    if array.ndim != 3 or array.shape[2] != 3:
        raise ValueError(f"{name} must be an H x W x 3 array, not of shape {array.shape}")
    if shape is not None and array.shape != shape:
        raise ValueError(f"{name} has shape {array.shape}, the image {shape}")
    return array
