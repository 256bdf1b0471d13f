"""``affine``: a Mitsuba texture that is another texture's value times a scale plus a bias, clipped to [0, 1].

UsdUVTexture's ``scale`` and ``bias`` tint an image per material (a recoloured façade, a garment's two colours on a
fabric mask). Baked into a bitmap per material they cost one copy of the image each (hundreds of megabytes for a
randomised crowd); as this texture over one shared bitmap per image they cost three numbers each. Registered by
:func:`register` for the active variant (:func:`synthua_usd.backends.mitsuba.variants.activate` does it); written
in Python, which the JIT variants trace into their kernels like Mitsuba's own plugins.
"""

from __future__ import annotations

#: The variants the plugin is registered for (one registration per variant and process).
_REGISTERED: set[str] = set()


def register(mi) -> None:
    """Register ``affine`` with the active variant of ``mi`` (once)."""
    variant = mi.variant()
    if variant in _REGISTERED:
        return
    import drjit as dr

    class AffineTexture(mi.Texture):
        """``clip(texture * scale + bias, 0, 1)`` per channel; ``texture`` a loaded texture, ``scale`` and ``bias``
        RGB."""

        def __init__(self, props) -> None:
            mi.Texture.__init__(self, props)
            self.texture = props["texture"]
            self.scale = mi.Color3f(props["scale"])
            self.bias = mi.Color3f(props["bias"])

        def eval(self, si, active=True):
            return dr.clip(self.texture.eval(si, active) * self.scale + self.bias, 0.0, 1.0)

        def eval_1(self, si, active=True):
            return mi.luminance(self.eval(si, active))

        def eval_3(self, si, active=True):
            return self.eval(si, active)

        def mean(self):
            return float(dr.mean(dr.clip(self.texture.mean() * self.scale + self.bias, 0.0, 1.0)))

        def is_spatially_varying(self):
            return True

        def traverse(self, callback) -> None:  # nothing to differentiate or update in place
            pass

        def parameters_changed(self, keys=[]) -> None:  # noqa: B006 (Mitsuba's signature)
            pass

        def to_string(self) -> str:
            return f"AffineTexture[scale={self.scale}, bias={self.bias}]"

    mi.register_texture("affine", lambda props: AffineTexture(props))
    _REGISTERED.add(variant)
