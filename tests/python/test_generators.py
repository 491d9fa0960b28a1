"""The table generators in tools/ reproduce the committed files byte for byte from the inputs
committed in data/: each runs into a temporary folder and its output is compared with the
repository's. A missing input makes its generator fail, and so the test."""

import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
TOOLS = ROOT / "tools"
SPECTRUM = ROOT / "crates" / "prism-core" / "src" / "spectrum"
CORNELL = ROOT / "scenes" / "cornell-box"


def run(script: str, *args: str) -> None:
    """Runs tools/SCRIPT with ARGS, failing the test with its output when it fails."""
    result = subprocess.run(
        [sys.executable, str(TOOLS / script), *args], capture_output=True, text=True
    )
    assert result.returncode == 0, f"{script} failed:\n{result.stdout}{result.stderr}"


def files_under(folder: Path) -> dict:
    """Every file under FOLDER, by its path relative to it."""
    return {p.relative_to(folder): p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()}


def test_cie_tables_are_reproduced(tmp_path: Path) -> None:
    out = tmp_path / "cie_tables.rs"
    run("gen_cie_tables.py", "--out", str(out))
    assert out.read_bytes() == (SPECTRUM / "cie_tables.rs").read_bytes()


def test_conductor_tables_are_reproduced(tmp_path: Path) -> None:
    out = tmp_path / "conductors.rs"
    run("gen_conductor_ior.py", "--out", str(out))
    assert out.read_bytes() == (SPECTRUM / "conductors.rs").read_bytes()


# Written by hand beside the generated scene: its pbrt-v4 transcription (docs/pbrt.md).
HAND_WRITTEN = {Path("scene.pbrt")}


def test_cornell_box_is_reproduced(tmp_path: Path) -> None:
    out = tmp_path / "cornell-box"
    run("gen_cornell_box.py", "--out", str(out))
    written = files_under(out)
    committed = {name: data for name, data in files_under(CORNELL).items() if name not in HAND_WRITTEN}
    assert sorted(written) == sorted(committed)
    for name, data in written.items():
        assert data == committed[name], f"{name} differs from scenes/cornell-box/{name}"


@pytest.mark.parametrize(
    "script, data",
    [
        ("gen_cie_tables.py", "cie"),
        ("gen_conductor_ior.py", "ior"),
        ("gen_cornell_box.py", "cornell_spectra.txt"),
    ],
)
def test_a_missing_input_fails(tmp_path: Path, script: str, data: str) -> None:
    missing = tmp_path / data
    result = subprocess.run(
        [sys.executable, str(TOOLS / script), "--data", str(missing), "--out", str(tmp_path / "o")],
        capture_output=True,
        text=True,
    )
    assert result.returncode != 0
