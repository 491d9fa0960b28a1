"""The command line the generators in tools/ share: `--data`, where the committed inputs are,
and `--out`, where the generated file or folder goes; both default to the repository's own.

Standard library only; a generator run as `python3 tools/NAME.py` finds this module beside it.
"""
import argparse
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def parse(doc, data, out, data_help=None, out_help=None):
    """The arguments of the generator whose docstring is `doc` (its first line describes it);
    `data` and `out` are the defaults, relative to the repository's root."""
    parser = argparse.ArgumentParser(description=doc.splitlines()[0])
    parser.add_argument("--data", type=Path, default=ROOT / data, help=data_help)
    parser.add_argument("--out", type=Path, default=ROOT / out, help=out_help)
    return parser.parse_args()
