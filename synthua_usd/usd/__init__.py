"""USD authoring and reading: the only part of synthua-usd that imports ``pxr``."""
