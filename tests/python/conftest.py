"""Shared fixtures: the repository's bundled Cornell box, as a file and as the equivalent
Mitsuba dictionary, and the `prism` command built beside the package."""

import os
import xml.etree.ElementTree as ElementTree
from pathlib import Path

import pytest

import prism_renderer as pr

ROOT = Path(__file__).resolve().parents[2]
CORNELL = ROOT / "scenes" / "cornell-box" / "scene.xml"

# Small enough to render in a fraction of a second.
SIZE = {"spp": 4, "resx": 24, "resy": 20}


@pytest.fixture(scope="session")
def cornell_path() -> Path:
    assert CORNELL.is_file(), f"{CORNELL} is missing"
    return CORNELL


@pytest.fixture(scope="session")
def prism_cli() -> Path:
    """The command-line program (PRISM_CLI, or target/release/prism, which .ci/run builds)."""
    path = Path(os.environ.get("PRISM_CLI", ROOT / "target" / "release" / "prism"))
    assert path.is_file(), f"{path} is missing: build it with cargo build --release"
    return path


def _spectrum_pairs(text: str) -> list:
    """'400:0.343, 404:0.445' as [(400.0, 0.343), (404.0, 0.445)]."""
    pairs = []
    for entry in text.split(","):
        wavelength, value = entry.strip().split(":")
        pairs.append((float(wavelength), float(value)))
    return pairs


@pytest.fixture(scope="session")
def cornell_dict(cornell_path: Path) -> dict:
    """The Cornell box of scene.xml at SIZE, written as a dictionary by hand; only the measured
    reflectance spectra are taken from the file, as lists of (wavelength, value) pairs."""
    spectra = {}
    for bsdf in ElementTree.parse(cornell_path).getroot().iter("bsdf"):
        spectrum = bsdf.find("spectrum")
        if spectrum is not None:
            spectra[bsdf.get("id")] = spectrum.get("value", "")
    meshes = cornell_path.parent / "meshes"

    def diffuse(name: str) -> dict:
        return {
            "type": "diffuse",
            "reflectance": {"type": "spectrum", "value": _spectrum_pairs(spectra[name])},
        }

    def mesh(name: str, bsdf: str, **extra) -> dict:
        return {
            "type": "obj",
            "filename": str(meshes / f"{name}.obj"),
            "bsdf": {"type": "ref", "id": bsdf},
            **extra,
        }

    return {
        "type": "scene",
        "integrator": {"type": "path", "max_depth": -1},
        "sensor": {
            "type": "perspective",
            "fov": 39.3077,
            "fov_axis": "smaller",
            "to_world": pr.Transform().look_at(
                origin=[278, 273, -800], target=[278, 273, -799], up=[0, 1, 0]
            ),
            "sampler": {"type": "independent", "sample_count": SIZE["spp"]},
            "film": {
                "type": "hdrfilm",
                "width": SIZE["resx"],
                "height": SIZE["resy"],
                "rfilter": {"type": "box"},
            },
        },
        "white": diffuse("white"),
        "green": diffuse("green"),
        "red": diffuse("red"),
        "luminaire": {"type": "diffuse", "reflectance": 0.78},
        "floor": mesh("floor", "white"),
        "ceiling": mesh("ceiling", "white"),
        "back_wall": mesh("back_wall", "white"),
        "right_wall": mesh("right_wall", "green"),
        "left_wall": mesh("left_wall", "red"),
        "short_block": mesh("short_block", "white"),
        "tall_block": mesh("tall_block", "white"),
        "light": mesh(
            "light",
            "luminaire",
            emitter={
                "type": "area",
                "radiance": {
                    "type": "spectrum",
                    "value": [(400, 0.0), (500, 8.0), (600, 15.6), (700, 18.4)],
                },
            },
        ),
    }


@pytest.fixture(scope="session")
def cornell(cornell_path: Path) -> "pr.Scene":
    return pr.load_file(cornell_path, **SIZE)
