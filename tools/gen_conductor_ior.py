#!/usr/bin/env python3
"""Writes crates/prism-core/src/spectrum/conductors.rs: the complex indices of refraction (eta, k)
of Mitsuba's named conductor presets, from the .spd files in data/ior (Mitsuba 3's
resources/data/ior, from the mitsuba-data repository; data/README.md). A preset whose data
equals another's (most `*_palik` files repeat their base material) becomes an alias of it.

usage: python3 tools/gen_conductor_ior.py [--data DIR] [--out FILE]
"""
import glob
import os
import struct
import sys

import generator_args

args = generator_args.parse(
    __doc__, "data/ior", "crates/prism-core/src/spectrum/conductors.rs", data_help="folder of the .spd files"
)
src, out = str(args.data), args.out


def f32(x):
    """The shortest decimal that rounds to the same single-precision number."""
    target = struct.unpack("f", struct.pack("f", x))[0]
    for digits in range(1, 10):
        text = f"{target:.{digits}g}"
        if struct.unpack("f", struct.pack("f", float(text)))[0] == target:
            break
    if "e" not in text and "." not in text:
        text += ".0"
    return text


def read(path):
    rows = []
    for line in open(path):
        line = line.strip()
        if not line or line.startswith("#"):
            continue
        lam, value = line.split()[:2]
        rows.append((float(lam), float(value)))
    return rows


names = sorted(os.path.basename(p)[: -len(".eta.spd")] for p in glob.glob(os.path.join(src, "*.eta.spd")))
if not names:
    sys.exit(f"gen_conductor_ior.py: no .eta.spd files in {src}")
data = {}
for name in names:
    eta = read(os.path.join(src, name + ".eta.spd"))
    k = read(os.path.join(src, name + ".k.spd"))
    assert [a for a, _ in eta] == [a for a, _ in k], name
    data[name] = [(lam, e, kk) for (lam, e), (_, kk) in zip(eta, k)]
# Shorter names first, so that "Cu" is the table and "Cu_palik" its alias.
aliases = {}
tables = []
for name in sorted(names, key=lambda n: (len(n), n)):
    same = next((t for t in tables if data[t] == data[name]), None)
    if same is None:
        tables.append(name)
    else:
        aliases[name] = same
tables.sort()
lines = [
    "//! Complex indices of refraction η + ik of Mitsuba's named conductor presets",
    "//! (`<string name=\"material\" value=\"Au\"/>`), tabulated over wavelength in nm.",
    "//!",
    "//! Source: the `.eta.spd`/`.k.spd` files of Mitsuba 3 (`resources/data/ior`, from the",
    "//! mitsuba-data repository), \"identical to the data distributed with PBRT. They are originally",
    "//! from the Luxpop database (www.luxpop.com) and are based on data by Palik et al. [Handbook of",
    "//! Optical Constants of Solids, 1998] and measurements of atomic scattering factors made by the",
    "//! Center For X-Ray Optics (CXRO) at Berkeley and the Lawrence Livermore National Laboratory",
    "//! (LLNL)\" (Mitsuba 3 documentation, `conductor`). Presets whose files hold the same data as",
    "//! another's are aliases of it ([`CONDUCTOR_ALIASES`]). Written by",
    "//! `tools/gen_conductor_ior.py`; do not edit.",
    "",
    "// Measured values that happen to be close to π or 2π are data, not approximations of them.",
    "#![allow(clippy::approx_constant)]",
    "",
    "/// A preset: its name and samples (λ in nm, η, k).",
    "pub struct ConductorData {",
    "    pub name: &'static str,",
    "    pub samples: &'static [(f32, f32, f32)],",
    "}",
    "",
    "/// The preset called `name` (a table's name or an alias).",
    "pub fn conductor_preset(name: &str) -> Option<&'static ConductorData> {",
    "    let name = CONDUCTOR_ALIASES",
    "        .iter()",
    "        .find(|(alias, _)| *alias == name)",
    "        .map_or(name, |(_, table)| table);",
    "    CONDUCTORS.iter().find(|c| c.name == name)",
    "}",
    "",
    "/// Every preset's name, tables and aliases, sorted.",
    "pub fn conductor_names() -> Vec<&'static str> {",
    "    let mut names: Vec<&str> = CONDUCTORS.iter().map(|c| c.name).collect();",
    "    names.extend(CONDUCTOR_ALIASES.iter().map(|(alias, _)| *alias));",
    "    names.sort_unstable();",
    "    names",
    "}",
    "",
    "/// Presets whose data equals another preset's: (alias, the preset it names).",
    "pub const CONDUCTOR_ALIASES: &[(&str, &str)] = &[",
]
for alias in sorted(aliases):
    lines.append(f"    (\"{alias}\", \"{aliases[alias]}\"),")
lines += ["];", "", "pub const CONDUCTORS: &[ConductorData] = &["]
for name in tables:
    lines.append("    ConductorData {")
    lines.append(f"        name: \"{name}\",")
    lines.append("        samples: &[")
    for lam, e, kk in data[name]:
        lines.append(f"            ({f32(lam)}, {f32(e)}, {f32(kk)}),")
    lines.append("        ],")
    lines.append("    },")
lines.append("];")
out.write_text("\n".join(lines) + "\n")
print(f"wrote {len(tables)} presets and {len(aliases)} aliases to {out}")
