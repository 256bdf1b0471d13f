"""``affine``: a Mitsuba texture that is another texture's value times a scale plus a bias, clipped to [0, 1].

UsdUVTexture's ``scale`` and ``bias`` tint an image per material (a recoloured façade, a garment's two colours on a
fabric mask). Baked into a bitmap per material they cost one copy of the image each (hundreds of megabytes for a
randomised crowd); as this texture over one shared bitmap per image they cost three numbers each, opaque to the
kernel (every tint shares its code). Registered by :func:`register` for the active variant (a translation's
:class:`synthua_usd.backends.mitsuba.surfaces.TextureImages` does it); written in Python
(:mod:`synthua_usd.backends.mitsuba.python_textures`).
"""

from __future__ import annotations

from synthua_usd.backends.mitsuba import python_textures


def register(mi) -> None:
    """Register ``affine`` with the active variant of ``mi`` (once)."""
    import drjit as dr

    def make(base: type) -> type:
        class AffineTexture(base):
            """``clip(texture * scale + bias, 0, 1)`` per channel; ``texture`` a loaded texture, ``scale`` and
            ``bias`` RGB."""

            def __init__(self, props) -> None:
                base.__init__(self, props)
                self.texture = props["texture"]
                scale, bias = props["scale"], props["bias"]
                # a scale and bias of their own, or textures giving the shape's (the rows of shape tables)
                self.per_shape = isinstance(scale, mi.Texture)
                if self.per_shape:
                    self.scale, self.bias = scale, bias
                else:
                    self.scale, self.bias = mi.Color3f(scale), mi.Color3f(bias)
                    # opaque, not constants of the kernel: every tint shares one piece of the path tracer's code
                    # (issue 39: a randomised district scene compiled 17.5 s of kernels with literal tints)
                    dr.make_opaque(self.scale, self.bias)

            def _tint(self, si, active):
                if self.per_shape:
                    return self.scale.eval(si, active), self.bias.eval(si, active)
                return self.scale, self.bias

            def eval(self, si, active=True):
                scale, bias = self._tint(si, active)
                return dr.clip(self.texture.eval(si, active) * scale + bias, 0.0, 1.0)

            def eval_1(self, si, active=True):
                return mi.luminance(self.eval(si, active))

            def mean(self):
                if self.per_shape:
                    return float(dr.mean(dr.clip(self.texture.mean() * self.scale.mean() + self.bias.mean(), 0.0, 1.0)))
                return float(dr.mean(dr.clip(self.texture.mean() * self.scale + self.bias, 0.0, 1.0)))

            def to_string(self) -> str:
                return f"AffineTexture[scale={self.scale}, bias={self.bias}]"

        return AffineTexture

    python_textures.register(mi, "affine", make)
