"""Is an estimator unbiased at low samples per pixel? The z-test of the mean of K independent
renders against a high-sample reference.

usage: PYTHON tools/seed_mean_ztest.py 'renders/*.exr' REFERENCE.exr

PYTHON is one with numpy and Mitsuba 3 (for reading OpenEXR), e.g. the virtual environment that
tools/mitsuba-render installs: ~/.cache/prism/mitsuba-3.9.1/bin/python.

A z-test of one 64-spp image against a reference rejects even an unbiased estimator when the
samples are heavy-tailed: each pixel's variance is estimated from its own 64 samples, so z follows
a heavy-tailed t-like law, not a normal one. The mean of K renders (seeds 1..K) has the
across-render variance of each pixel as its error, from K independent values, and tests the
64-spp estimator's expectation itself: z = (mean - reference) / sqrt(var_K / K + var_reference),
with var_K the pixel's variance of Y across the renders and var_reference the reference's
`variance.Y` channel. Prints chi^2 / n, max |z| with its Bonferroni p-value, the share beyond
|z| = 3, and the ratio of the across-render variance to the mean of the renders' own
`variance.Y` (1 when the variance channels are honest).
"""
import glob
import math
import sys

import mitsuba as mi
import numpy as np


def channels(path):
    bitmap = mi.Bitmap(path)
    names = [bitmap.struct_()[i].name for i in range(bitmap.channel_count())]
    values = np.array(bitmap, copy=False)
    return {name: values[..., i].astype(np.float64) for i, name in enumerate(names)}


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    mi.set_variant("scalar_rgb")
    files = sorted(glob.glob(sys.argv[1]))
    if len(files) < 2:
        sys.exit(f"need at least two renders, found {len(files)} for {sys.argv[1]}")
    renders = [channels(f) for f in files]
    y = np.stack([r["Y"] for r in renders])
    own = np.stack([r["variance.Y"] for r in renders]).mean(0)
    reference = channels(sys.argv[2])
    across = y.var(0, ddof=1)
    z = (y.mean(0) - reference["Y"]) / np.sqrt(across / len(files) + reference["variance.Y"])
    z = z[np.isfinite(z)]
    n = z.size
    max_z = np.abs(z).max()
    bonferroni = min(1.0, n * math.erfc(max_z / math.sqrt(2)))
    print(f"{len(files)} renders against {sys.argv[2]} over {n} pixels: chi^2/n {np.mean(z * z):.3f} "
          f"(standard deviation {math.sqrt(2 / n):.3f}), max |z| {max_z:.2f} (Bonferroni p = "
          f"{bonferroni:.3f}), {100 * np.mean(np.abs(z) > 3):.2f} % beyond |z| = 3 (0.27 % "
          f"expected), mean z {np.mean(z):+.3f}; across-render variance / variance.Y "
          f"{across.sum() / own.sum():.3f}")


if __name__ == "__main__":
    main()
