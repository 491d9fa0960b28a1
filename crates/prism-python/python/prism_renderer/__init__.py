"""Prism, a spectral Monte Carlo path tracer for Mitsuba 3 scenes, from Python.

    import prism_renderer as pr
    scene = pr.load_file("scenes/cornell-box/scene.xml", spp=16)
    image = pr.render(scene, seed=1)
    image.rgb            # numpy array, H x W x 3, linear sRGB (np.asarray(image) too)
    image.write("cornell.exr")
    params = pr.traverse(scene)                # Mitsuba's keys: params["sensor.x_fov"] = 30
    params["luminaire.reflectance.value"] = 0.5
    params.update()                            # rebuilt from the edited description
    pr.write_image("red.png", np.full((8, 8, 3), [1.0, 0.0, 0.0], np.float32))
    pixels = pr.read_image("mitsuba.exr")   # any EXR, PNG, JPEG or HDR as a float32 array
    parts = [pr.render(scene, seed=1, sample_range=(s, s + 4)) for s in (0, 4, 8, 12)]
    pr.merge(parts).image()                    # a farm's parts: the one render, bit for bit

The API follows Mitsuba's (``load_file``, ``load_dict``, ``render``), and Mitsuba's own names
(``set_variant``, ``load_string``, ``ScalarTransform4f``, ``util.write_bitmap``,
``cornell_box``) let its scripts run with ``import prism_renderer as mi``; the scene is read, checked
and rendered by the same Rust code as the ``prism`` command, so the images and error messages
are the same. See docs/python.md.
"""

from __future__ import annotations

import math
import os
import sys
import time
from typing import Any, Callable, Optional, Sequence, Tuple, Union, overload

import numpy as np
import numpy.typing as npt

from ._native import (
    BoundingBox3f,
    ChannelDifference,
    Comparison,
    Emitter,
    Image,
    PrismError,
    Ray3f,
    RenderState,
    Scene,
    SceneParameters,
    Sensor,
    Shape,
    SurfaceInteraction,
    Transform,
    ZTest,
    load_dict,
    merge,
    traverse,
)
from . import _native, util
from ._denoise import denoise
from ._variants import set_variant, variant, variants
from .util import cornell_box

ScalarTransform4f = Transform
"""Mitsuba's name of :class:`Transform`."""

__all__ = [
    "BoundingBox3f",
    "ChannelDifference",
    "Comparison",
    "Emitter",
    "Image",
    "PrismError",
    "Ray3f",
    "RenderState",
    "Scene",
    "SceneParameters",
    "ScalarTransform4f",
    "Sensor",
    "Shape",
    "SurfaceInteraction",
    "Transform",
    "ZTest",
    "compare",
    "cornell_box",
    "denoise",
    "load_dict",
    "load_file",
    "load_string",
    "merge",
    "read_image",
    "render",
    "set_variant",
    "traverse",
    "util",
    "variant",
    "variants",
    "write_image",
]

ProgressCallback = Callable[[int, Optional[int], float], object]
PreviewCallback = Callable[[Image], object]


def load_file(path: Union[str, os.PathLike], **defines: object) -> Scene:
    """Loads the Mitsuba XML scene at ``path``, or the pbrt-v4 scene when its name ends in
    ``.pbrt`` (docs/pbrt.md; a pbrt scene takes no keywords).

    Each keyword sets a ``<default>`` parameter of the scene, like ``prism render -D name=value``
    (``load_file("scene.xml", spp=16, resx=64)``); values are written as text, booleans as
    ``true``/``false``. A scene that is not valid raises :class:`PrismError` with the ``file``,
    ``line`` and ``column`` of the problem.
    """
    pairs = [(name, _define_text(value)) for name, value in defines.items()]
    return _native.load_file(os.fspath(path), pairs)


def load_string(text: str, **defines: object) -> Scene:
    """Loads a Mitsuba XML scene given as the string ``text``, as Mitsuba's ``load_string``:
    keywords set its ``<default>`` parameters as in :func:`load_file`, relative file names are
    found from the current folder, and a :class:`PrismError` names the text ``<string>``."""
    pairs = [(name, _define_text(value)) for name, value in defines.items()]
    return _native.load_string(text, pairs)


def _define_text(value: object) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    return str(value)


@overload
def render(
    scene: Scene,
    spp: Optional[int] = ...,
    seed: Optional[int] = ...,
    threads: Optional[int] = ...,
    progress: Union[bool, ProgressCallback] = ...,
    time_limit: Optional[float] = ...,
    target_error: Optional[float] = ...,
    preview: Optional[PreviewCallback] = ...,
    sensor: Union[int, str] = ...,
    crop: Optional[Tuple[int, int, int, int]] = ...,
    checkpoint: Optional[Union[str, os.PathLike]] = ...,
    checkpoint_every: float = ...,
    resume: Optional[Union[str, os.PathLike]] = ...,
    sample_range: None = ...,
) -> Image: ...


@overload
def render(
    scene: Scene,
    spp: Optional[int] = ...,
    seed: Optional[int] = ...,
    threads: Optional[int] = ...,
    progress: Union[bool, ProgressCallback] = ...,
    time_limit: Optional[float] = ...,
    target_error: Optional[float] = ...,
    preview: Optional[PreviewCallback] = ...,
    sensor: Union[int, str] = ...,
    crop: Optional[Tuple[int, int, int, int]] = ...,
    checkpoint: Optional[Union[str, os.PathLike]] = ...,
    checkpoint_every: float = ...,
    resume: Optional[Union[str, os.PathLike]] = ...,
    *,
    sample_range: Tuple[int, int],
) -> RenderState: ...


def render(
    scene: Scene,
    spp: Optional[int] = None,
    seed: Optional[int] = None,
    threads: Optional[int] = None,
    progress: Union[bool, ProgressCallback] = True,
    time_limit: Optional[float] = None,
    target_error: Optional[float] = None,
    preview: Optional[PreviewCallback] = None,
    sensor: Union[int, str] = 0,
    crop: Optional[Tuple[int, int, int, int]] = None,
    checkpoint: Optional[Union[str, os.PathLike]] = None,
    checkpoint_every: float = 60.0,
    resume: Optional[Union[str, os.PathLike]] = None,
    sample_range: Optional[Tuple[int, int]] = None,
) -> Union[Image, RenderState]:
    """Renders ``scene`` and returns its :class:`Image`.

    ``spp``: samples per pixel (default: the sampler's ``sample_count``). ``seed``: the seed of
    every random stream (default: the sampler's ``seed``, 0 unless the scene sets it); the image
    is the same for a seed whatever the number of ``threads`` (default: one per core) and equal
    to ``prism render --seed``'s. With ``time_limit`` (seconds) or ``target_error`` (the image's
    mean relative standard error) the render stops at whichever comes first, ``spp`` then only
    capping the samples. ``sensor``: which ``<sensor>`` of a scene with several to look
    through, its index from 0 in document order or its ``id`` (as Mitsuba's
    ``mi.render(scene, sensor=...)`` and ``prism render --sensor``).

    ``crop=(x0, y0, x1, y1)``: render only the pixels x0 <= x < x1, y0 <= y < y1 of the film
    (the scene is held exclusively while it renders). ``checkpoint``: save the render state to
    this file every ``checkpoint_every`` seconds and at the end. ``resume``: continue the render
    saved in this state (with the same scene, ``spp``, ``seed`` and ``crop``), saving to it
    unless ``checkpoint`` names another file. These are ``prism render``'s ``--crop``,
    ``--checkpoint``, ``--checkpoint-every`` and ``--resume``: the state files are the same, and
    so is the image, bit for bit.

    ``sample_range=(start, end)``: take only the samples start <= i < end of every pixel (of
    the ``spp`` the stratification is made for) and return their :class:`RenderState` in place
    of the image, as ``prism render --sample-range``: a render farm's task. :func:`merge` adds
    the states of disjoint ranges into the state of one render of all their samples, whose
    ``image()`` is bit for bit the single render's.

    ``progress``: True shows a progress bar (tqdm's, in a terminal or a notebook, if tqdm is
    installed; else a line on standard error), False none; a callable is called as
    ``progress(samples, total, error)`` about ten times a second.

    ``preview``: a callable called as ``preview(image)`` with the developing :class:`Image`
    after passes (the newest, when several finished since the last call; ``image.spp`` says how
    many samples it holds), the last image shown equal to the one ``render`` returns: to show a
    render as it develops (in a notebook, say).

    The render runs on worker threads without the GIL, so other Python threads keep running.
    Ctrl-C stops it: the worker threads finish their tiles and are joined, and
    KeyboardInterrupt is raised; an exception raised by ``progress`` or ``preview`` stops it the
    same way.
    """
    callback: Optional[ProgressCallback]
    bar: Optional[_ProgressBar] = None
    if callable(progress):
        callback = progress
    elif progress:
        bar = _ProgressBar()
        callback = bar
    else:
        callback = None
    try:
        return _native.render(
            scene,
            {
                "spp": spp,
                "seed": seed,
                "threads": threads,
                "time_limit": time_limit,
                "target_error": target_error,
                "sensor": sensor,
                "crop": crop,
                "checkpoint": None if checkpoint is None else os.fspath(checkpoint),
                "checkpoint_every": float(checkpoint_every),
                "resume": None if resume is None else os.fspath(resume),
                "sample_range": sample_range,
            },
            callback,
            preview,
        )
    finally:
        if bar is not None:
            bar.close()


def compare(
    test: Union[Image, str, os.PathLike],
    reference: Union[Image, str, os.PathLike],
    channels: Optional[Sequence[str]] = None,
    diff: Optional[Union[str, os.PathLike]] = None,
) -> Comparison:
    """Compares ``test`` with ``reference`` (each an :class:`Image` or an EXR file's path) as
    ``prism compare`` does: per channel the means, MSE, relative MSE and largest difference,
    and the per-pixel z-test of luminance when the test image has variances. ``str()`` of the
    result is ``prism compare``'s table. ``diff``: a PNG file to write the signed difference
    to in false colour (red where the test is brighter, blue where darker), as
    ``prism compare --diff``."""

    def operand(value: Union[Image, str, os.PathLike]) -> Union[Image, str]:
        return value if isinstance(value, Image) else os.fspath(value)

    return _native.compare(
        operand(test),
        operand(reference),
        None if channels is None else list(channels),
        None if diff is None else os.fspath(diff),
    )


def read_image(
    path: Union[str, os.PathLike], channels: Optional[Sequence[str]] = None
) -> npt.NDArray[np.float32]:
    """The linear values of an image file as a float32 array, H x W x C, or H x W for one
    channel.

    OpenEXR (Prism's, Mitsuba's or any renderer's; 32-bit or half floats): the channels named
    by ``channels``, or else the first of R,G,B,A / R,G,B / X,Y,Z,A / X,Y,Z / Y,A / Y the
    file has in full, or else all of its channels in the file's (alphabetical) order. PNG
    and JPEG: decoded from the sRGB curve to linear values in [0, 1] (alpha as stored); a grey
    image with alpha gives RGBA. Radiance HDR: as stored.
    """
    return _native.read_image(os.fspath(path), None if channels is None else list(channels))


def write_image(
    path: Union[str, os.PathLike],
    array: npt.ArrayLike,
    channels: Optional[Sequence[str]] = None,
) -> None:
    """Writes an H x W or H x W x C array of linear values as an image file.

    ``.exr``: one OpenEXR channel per C, named ``channels`` (default: Y; Y,A; R,G,B; R,G,B,A
    for 1 to 4 channels), stored as half floats if the array's dtype is float16, else as
    32-bit floats. ``.png`` (1 to 4 channels: grey, grey and alpha, RGB, RGBA) and ``.jpg`` or
    ``.jpeg`` (1 or 3 channels, quality 100): 8-bit values through the sRGB curve, alpha stored
    linearly, all clamped to [0, 1]. :func:`read_image` reads them back.
    """
    values = np.asarray(array)
    half = values.dtype == np.float16
    values = np.ascontiguousarray(values, dtype=np.float32)
    _native.write_image(
        os.fspath(path), values, None if channels is None else list(channels), half
    )


class _ProgressBar:
    """tqdm's bar (``tqdm.auto``: a widget in Jupyter) if tqdm is installed, else a line on
    standard error rewritten twice a second."""

    def __init__(self) -> None:
        self._tqdm: Any = None
        try:
            from tqdm.auto import tqdm

            self._tqdm = tqdm
        except ImportError:
            pass
        self._bar: Any = None
        self._samples = 0
        self._last_line = -math.inf
        self._line_shown = False

    def __call__(self, samples: int, total: Optional[int], error: float) -> None:
        message = f"error {error:.4f}" if math.isfinite(error) else ""
        if self._tqdm is not None:
            if self._bar is None:
                self._bar = self._tqdm(
                    total=total, unit=" samples", unit_scale=True, desc="prism", leave=False
                )
            self._bar.update(samples - self._samples)
            self._samples = samples
            if message:
                self._bar.set_postfix_str(message, refresh=False)
            return
        now = time.monotonic()
        if now - self._last_line < 0.5 and (total is None or samples < total):
            return
        self._last_line = now
        if total:
            line = f"prism: {100.0 * samples / total:5.1f} % of {total} samples"
        else:
            line = f"prism: {samples} samples"
        if message:
            line += ", " + message
        sys.stderr.write("\r" + line)
        sys.stderr.flush()
        self._line_shown = True

    def close(self) -> None:
        if self._bar is not None:
            self._bar.close()
        elif self._line_shown:
            sys.stderr.write("\n")
            sys.stderr.flush()
