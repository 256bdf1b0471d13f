"""The stated limits and defaults of `synthua train` and `synthua evaluate-real`: ranges of their options.

Kept apart from the modules that use them so that the command line can build its options without loading the
readers, the assets or the runner. Each limit says why it is where it is.
"""

from __future__ import annotations

from synthua_usd.model.ranges import Range

#: Training budget: from 3 seconds (a smoke test) to a week.
MINUTES = Range(0.05, 10_080, "min")
DEFAULT_MINUTES = 30.0
EPOCHS = Range(1, 100_000, integer=True)
#: Image size (long side): the model's stride is 32; above 4096 a CPU run never ends and a GPU runs out of memory.
IMGSZ = Range(32, 4096, "px", integer=True)
DEFAULT_IMGSZ = 320
BATCH = Range(1, 1024, integer=True)
DEFAULT_BATCH = 16
#: Epochs at the end of a training without mosaic augmentation (Ultralytics' ``close_mosaic``, its default 10).
CLOSE_MOSAIC = Range(0, 100_000, integer=True)
DEFAULT_CLOSE_MOSAIC = 10
#: Boxes lower than this (pixels of the generated image) are neither trained on nor scored; 8 px: below it a
#: person is a few pixels of colour at 320 px, and no real test set labels them.
MIN_HEIGHT_PX = Range(0.0, 10_000.0, "px")
DEFAULT_MIN_HEIGHT_PX = 8.0
#: Confidence of precision, recall and false negatives (and the IoU of merging model classes): (0, 1); 1 itself is
#: refused by the request (no detection scores above it).
CONFIDENCE = Range(0.0, 1.0, low_open=True)
DEFAULT_CONFIDENCE = 0.25
#: The architecture trained by default: Ultralytics' smallest current detector (YOLO26 nano, 2.5 M parameters).
DEFAULT_MODEL = "yolo26n.yaml"
DEVICES = ("auto", "cpu", "cuda")
#: Which boxes of a composite (`synthua composite`) are scored: ``all``; ``pasted``, its pasted instances' alone;
#: ``photo``, its photo's own alone. The others are kept as ``ignore`` (neither required nor penalised), so a
#: detection on the photo's own wheelchair user is no false positive of the pastes' score, nor the reverse.
SCORED_BOXES = ("all", "pasted", "photo")
