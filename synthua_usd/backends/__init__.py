"""Backends: the renderers (Mitsuba; Blender Cycles for comparisons) and the work on rendered pixels (weather,
exposure, denoising, camera effects, compositing, previews). The only code that imports ``mitsuba``; image files are
written through :mod:`synthua_usd.core.images`."""
