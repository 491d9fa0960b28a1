"""Mitsuba 3's variant names (``variants``, ``set_variant``, ``variant``), so that scripts
written for Mitsuba run unchanged.

Mitsuba compiles one renderer per variant: a backend (``scalar``, ``llvm``, ``cuda``), with or
without automatic differentiation (``_ad``), and a colour model (``mono``, ``rgb``,
``spectral``, optionally ``_polarized``). Prism has one renderer, a spectral path tracer on the
CPU: it accepts the spectral names, all of which render the same, and refuses the others with
a message that says why.
"""

from __future__ import annotations

from typing import List, Optional

_SPECTRAL = (
    "scalar_spectral",
    "llvm_spectral",
    "llvm_ad_spectral",
    "cuda_spectral",
    "cuda_ad_spectral",
)

_variant: Optional[str] = None


def variants() -> List[str]:
    """The variant names :func:`set_variant` accepts: Mitsuba's spectral ones. All render
    with Prism's spectral path tracer on the CPU (no derivatives, no GPU)."""
    return list(_SPECTRAL)


def variant() -> Optional[str]:
    """The name last given to :func:`set_variant`, or None before it is called (as in
    Mitsuba)."""
    return _variant


def set_variant(*names: str) -> None:
    """Selects the first of ``names`` that Prism accepts (see :func:`variants`), as Mitsuba's
    ``set_variant('cuda_ad_spectral', 'scalar_spectral')`` takes the first available. Raises
    ImportError, as Mitsuba does, when none is accepted: ``mono`` and ``rgb`` variants because
    Prism renders spectrally (every camera sample carries wavelengths and the materials'
    spectra; RGB values in a scene are upsampled to spectra), ``polarized`` ones because it
    does not track polarization."""
    global _variant
    for name in names:
        if name in _SPECTRAL:
            _variant = name
            return
    raise ImportError(_refusal(names))


def _refusal(names: tuple) -> str:
    requested = ", ".join(f'"{name}"' for name in names) or "no variant"
    parts = set("_".join(names).split("_"))
    if parts & {"rgb", "mono"}:
        reason = (
            "Prism renders spectrally: every camera sample carries wavelengths, and RGB values "
            "in a scene are upsampled to spectra, so there is no RGB or monochrome mode"
        )
    elif "polarized" in parts:
        reason = "Prism does not track polarization"
    else:
        reason = "Prism knows no such variant"
    return (
        f"Requested an unsupported variant {requested}: {reason}. "
        f"Use one of {', '.join(_SPECTRAL)} (all render the same)."
    )
