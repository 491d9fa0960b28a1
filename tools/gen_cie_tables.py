#!/usr/bin/env python3
"""Writes crates/prism-core/src/spectrum/cie_tables.rs from the CIE data files in data/cie/.

usage: python3 tools/gen_cie_tables.py [--data DIR] [--out FILE]

The tables are embedded at 5 nm from 360 to 830 nm (95 values each): the CIE files' values at
every fifth nanometre, which are the CIE's 5 nm tables (D65 is cut to the same range). Prism
interpolates them linearly, as Mitsuba 3 does (docs/wavelengths.md says why), and the two
constants are the exact integrals of those interpolants. Arrays are laid out as `cargo fmt` lays them out (one
value per line when a value is longer than 10 characters, else as many per line as fit in 99
columns), so the written file is the committed one byte for byte.
"""
import csv

import generator_args

args = generator_args.parse(
    __doc__, "data/cie", "crates/prism-core/src/spectrum/cie_tables.rs", data_help="folder of the CIE CSV files"
)

cmf = {}
with open(args.data / "CIE_xyz_1931_2deg.csv") as f:
    for row in csv.reader(f):
        cmf[int(row[0])] = tuple(row[1:4])
d65 = {}
with open(args.data / "CIE_std_illum_D65.csv") as f:
    for row in csv.reader(f):
        d65[int(row[0])] = row[1]

lambdas = range(360, 831, 5)
assert all(l in cmf and l in d65 for l in lambdas)
STEP = 5.0


# rustfmt's `short_array_element_width_threshold`: arrays of values no longer than this are packed.
SHORT_VALUE = 10


def table(name, doc, values):
    values = [v.strip() if any(c in v for c in ".eE") else v.strip() + ".0" for v in values]
    out = [f"/// {doc}", f"pub const {name}: [f32; {len(values)}] = ["]
    if max(len(v) for v in values) > SHORT_VALUE:
        out += [f"    {v}," for v in values]
    else:
        line = "   "
        for v in values:
            item = f" {v},"
            if len(line) + len(item) > 99:
                out.append(line)
                line = "   "
            line += item
        out.append(line)
    out.append("];")
    return "\n".join(out)


lines = []


def emit(text=""):
    lines.append(text)


emit("""//! CIE 1931 2-degree colour matching functions and the CIE standard illuminant D65, at 5 nm from
//! 360 nm to 830 nm.
//!
//! Source: CIE (2019), "CIE 1931 colour-matching functions, 2 degree observer", dataset
//! DOI 10.25039/CIE.DS.xvudnb9b, and CIE (2022), "CIE standard illuminant D65", dataset
//! DOI 10.25039/CIE.DS.hjfjmt59; both © CIE, licensed CC BY-SA 4.0. Generated from the official
//! CSV files by `tools/gen_cie_tables.py`; do not edit by hand.
""")
emit("#![allow(clippy::excessive_precision)] // the CIE's digits, kept as published")
emit()
ys = [float(cmf[l][1]) for l in lambdas]
ds = [float(d65[l]) for l in lambdas]
# The exact integrals of the linear interpolants: the trapezoid rule for y-bar, and for the
# product of two linear functions over a cell h (a0 b0 / 3 + (a0 b1 + a1 b0) / 6 + a1 b1 / 3).
integral_y = STEP * (sum(ys) - 0.5 * (ys[0] + ys[-1]))
integral_d65_y = STEP * sum(
    a0 * b0 / 3 + (a0 * b1 + a1 * b0) / 6 + a1 * b1 / 3
    for a0, a1, b0, b1 in zip(ds, ds[1:], ys, ys[1:])
)
emit("/// The integral of y-bar in nm: of its linear interpolant between the table's values.")
emit(f"pub const CIE_Y_INTEGRAL: f64 = {integral_y!r};")
emit()
emit("/// Mean of D65 weighted by y-bar, both interpolated linearly: the integral of D65 y-bar over")
emit("/// the integral of y-bar. Dividing D65 by it gives an illuminant of luminance Y = 1.")
emit(f"pub const D65_LUMINANCE: f64 = {integral_d65_y / integral_y!r};")
emit()
emit("/// Wavelength of the first entry of every table, in nm.")
emit("pub const TABLE_LAMBDA_MIN: f32 = 360.0;")
emit()
emit("/// Spacing of the tables' entries, in nm.")
emit("pub const TABLE_STEP: f32 = 5.0;")
emit()
emit(table("CIE_X", "x-bar(lambda), 360..=830 nm at 5 nm.", [cmf[l][0] for l in lambdas]))
emit()
emit(table("CIE_Y", "y-bar(lambda), 360..=830 nm at 5 nm.", [cmf[l][1] for l in lambdas]))
emit()
emit(table("CIE_Z", "z-bar(lambda), 360..=830 nm at 5 nm.", [cmf[l][2] for l in lambdas]))
emit()
emit(table("D65", "Relative spectral power of D65 (100 at 560 nm), 360..=830 nm at 5 nm.", [d65[l] for l in lambdas]))
args.out.write_text("\n".join(lines) + "\n")
