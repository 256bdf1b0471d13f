"""A PyTorch ``Dataset`` over a generated dataset, returning targets in torchvision's formats without
importing torchvision (``pip install 'synthua-usd[torch]'``; torch is imported when this module is).

Item ``i`` is ``(image, target)``:

* ``image``: (3, H, W) float32 in [0, 1], the display sRGB image (``images/{split}/{name}.png``);
* ``target`` (torchvision's detection / instance-segmentation target, plus the semantic map):
  ``boxes`` (N, 4) float32 XYXY pixel edges; ``labels`` (N,) int64 class ids; ``masks`` (N, H, W) uint8;
  ``area`` (N,) float32 visible pixels; ``iscrowd`` (N,) int64, 1 for an instance too small to learn from (the config's ``min_instance_px``,
  iscrowd 1 in COCO too; torchvision's detection references leave those out of training); ``image_id`` int; ``semantic`` (H, W)
  int64 class ids of ``frames/{name}/class.png`` (0 = unlabelled); ``name`` str.

Instances are the image's visible thing instances as in its COCO annotations (decoded from the record's RLE
masks), in record order. QA-rejected images are left out, as in every training format.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import torch

from synthua_usd.analytics.dataset_index import dataset_manifest
from synthua_usd.core.errors import InputError
from synthua_usd.dataset.layout import SPLITS, Layout
from synthua_usd.dataset.manifest import kept_images
from synthua_usd.dataset.record import read_record


def collate(batch):
    """``DataLoader`` collate for detection: a tuple of images and a tuple of targets (sizes differ)."""
    return tuple(zip(*batch))


class SynthuaDataset(torch.utils.data.Dataset):
    """Images and targets of a dataset folder (``root``), of ``split`` or all splits; ``transforms`` is
    called as ``transforms(image, target)`` and returns both, as torchvision's reference scripts do."""

    def __init__(self, root: str | Path, split: str | None = None, transforms=None):
        if split is not None and split not in SPLITS:
            raise InputError(f"split: {split!r}; expected one of {', '.join(SPLITS)}")
        self.root = Path(root)
        self.layout = Layout(self.root)
        self.entries = kept_images(dataset_manifest(self.root), split)
        self.transforms = transforms

    def __len__(self) -> int:
        return len(self.entries)

    def _png(self, relative: str) -> np.ndarray:
        from synthua_usd.core.images import read_image

        return read_image(self.layout.path(relative))[0]

    def __getitem__(self, i: int):
        from pycocotools import mask as mask_utils

        entry = self.entries[i]
        name, split = entry["name"], entry["split"]
        record = read_record(self.layout.path(Layout.record(name)))
        rgb = self._png(Layout.rgb_png(split, name))[..., :3]
        semantic = self._png(Layout.frame_file(name, "class"))[..., 0]
        h, w = semantic.shape
        things = [inst for inst in record["instances"] if inst["isthing"] and inst["area"] > 0]
        if things:
            masks = mask_utils.decode([inst["segmentation"] for inst in things]).transpose(2, 0, 1)
        else:
            masks = np.zeros((0, h, w), np.uint8)
        boxes = np.array([[x, y, x + bw, y + bh] for x, y, bw, bh in (inst["bbox"] for inst in things)],
                         np.float32).reshape(-1, 4)
        target = {"boxes": torch.from_numpy(boxes),
                  "labels": torch.tensor([int(inst["category_id"]) for inst in things], dtype=torch.int64),
                  "masks": torch.from_numpy(np.ascontiguousarray(masks, np.uint8)),
                  "area": torch.tensor([float(inst["area"]) for inst in things], dtype=torch.float32),
                  "iscrowd": torch.tensor([int(inst["ignore"]) for inst in things], dtype=torch.int64),
                  "image_id": int(record["id"]),
                  "semantic": torch.from_numpy(semantic.astype(np.int64)),
                  "name": name}
        image = torch.from_numpy(np.ascontiguousarray(rgb.transpose(2, 0, 1))).float() / 255.0
        if self.transforms is not None:
            image, target = self.transforms(image, target)
        return image, target
