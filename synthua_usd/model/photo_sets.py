"""Which photos of a labelled set a command reads: the split names, kept apart from the readers so that the command
line can offer them without loading the readers (``synthua composite --split``)."""

from __future__ import annotations

#: The split that takes every split of a YOLO set.
ALL_SPLITS = "all"
#: A background set's default (:func:`synthua_usd.pipeline.backgrounds.read_backgrounds`): a labelled YOLO set's
#: train split where it names one, else all its photos (its val and test photos are what a detector trained on the
#: composites is scored on).
DEFAULT_SPLIT = "default"
#: What ``synthua composite --split`` takes.
SPLIT_CHOICES = (DEFAULT_SPLIT, "train", "val", "test", ALL_SPLITS)
