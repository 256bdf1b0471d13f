"""synthua-usd: layered OpenUSD street scenes rendered into exactly labelled image datasets.

Layers, imported in one direction (STYLE.md):

* plain data and documents (this package's top-level modules: taxonomy, cameras, scene, findings),
* USD authoring and reading (:mod:`synthua_usd.usd`, the only code that imports ``pxr``),
* backends (:mod:`synthua_usd.backends`, the only code that imports ``mitsuba`` or writes image files).
"""

__version__ = "0.1.0"
