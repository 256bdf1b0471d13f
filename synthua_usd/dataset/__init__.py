"""Datasets as plain data: the folder layout, per-image annotations, the training formats, generation
configs, sampling, quality checks and the manifest. Nothing here knows USD or a renderer."""
