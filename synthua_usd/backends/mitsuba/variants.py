"""Choosing and activating the Mitsuba variant: the one place that calls ``mi.set_variant``."""

from __future__ import annotations

import logging

from synthua_usd.core.errors import InputError

log = logging.getLogger(__name__)

#: Tried in this order when the user names none.
PREFERENCE = ("cuda_ad_rgb", "llvm_ad_rgb", "scalar_rgb")
#: LLVM 14/15 abort inside Dr.Jit ("Cannot select ... fminimum"); 19 is the oldest we have seen work.
MIN_LLVM = (19, 0, 0)


def _backend_ok(variant: str) -> bool:
    import drjit as dr

    if variant.startswith("cuda_"):
        return bool(dr.has_backend(dr.JitBackend.CUDA))
    if variant.startswith("llvm_"):
        if not dr.has_backend(dr.JitBackend.LLVM):
            return False
        version = tuple(dr.detail.llvm_version())
        if version < MIN_LLVM:
            log.info("libLLVM %s is older than %s; skipping %s", version, MIN_LLVM, variant)
            return False
        return True
    return True


def activate(requested: str | None = None):
    """Set and return the Mitsuba module with ``requested`` (or the best available rgb variant) active."""
    import mitsuba as mi

    if requested is not None:
        if requested not in mi.variants():
            raise InputError(f"variant '{requested}' is not in this Mitsuba build; available: {', '.join(mi.variants())}")
        if not requested.endswith("_rgb"):
            raise InputError(f"variant '{requested}' is not an RGB variant; use one of {', '.join(PREFERENCE)}")
        if not _backend_ok(requested):
            raise InputError(f"variant '{requested}' cannot run here (no CUDA device, or no libLLVM >= "
                             f"{'.'.join(map(str, MIN_LLVM))}); try scalar_rgb")
        mi.set_variant(requested)
        return mi
    for variant in PREFERENCE:
        if variant in mi.variants() and _backend_ok(variant):
            mi.set_variant(variant)
            log.info("Mitsuba variant %s", variant)
            return mi
    raise InputError(f"no usable Mitsuba RGB variant among {', '.join(PREFERENCE)}")
