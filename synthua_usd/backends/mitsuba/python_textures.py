"""Textures of ours written in Python (``affine``, ``face_weight``): what every one of them shares, and their
registration with Mitsuba, once per variant and process.

Mitsuba's JIT variants trace a Python texture into their kernels like its own plugins. A texture class must derive
from the ``mi.Texture`` of the active variant, so the shared base is made per variant (:func:`texture_base`).
"""

from __future__ import annotations

from typing import Callable

#: (variant, plugin name) pairs registered in this process.
_REGISTERED: set[tuple[str, str]] = set()
_BASES: dict[str, type] = {}


def texture_base(mi) -> type:
    """A ``mi.Texture`` subclass for the active variant with what our textures share: spatially varying, nothing
    to differentiate or update in place, ``eval_3`` as ``eval``; a subclass defines ``eval`` and ``eval_1``."""
    variant = mi.variant()
    if variant not in _BASES:
        class PythonTexture(mi.Texture):
            def eval_3(self, si, active=True):
                return self.eval(si, active)

            def is_spatially_varying(self):
                return True

            def traverse(self, callback) -> None:
                pass

            def parameters_changed(self, keys=[]) -> None:  # noqa: B006 (Mitsuba's signature)
                pass

        _BASES[variant] = PythonTexture
    return _BASES[variant]


def register(mi, name: str, make_class: Callable[[type], type]) -> None:
    """Register the texture ``name`` with the active variant of ``mi`` (once): ``make_class`` is given
    :func:`texture_base`'s class and returns the plugin's class."""
    key = (mi.variant(), name)
    if key in _REGISTERED:
        return
    cls = make_class(texture_base(mi))
    mi.register_texture(name, lambda props: cls(props))
    _REGISTERED.add(key)
