"""The PyTorch dataset: torchvision's target formats, checked against the hand-made dataset's pictures and
against a generated dataset's instance.png; skipped without torch."""

from __future__ import annotations

import importlib.util
import json

import numpy as np
import pytest
from PIL import Image

from analytics import tiny_dataset

if importlib.util.find_spec("torch") is None:  # found without importing it: collecting the suite stays light
    pytest.skip("torch is an optional extra: pip install 'synthua-usd[torch]'", allow_module_level=True)


@pytest.fixture(scope="module")
def torch():
    import torch

    return torch


@pytest.fixture(scope="module")
def torch_dataset(torch):
    from synthua_usd.analytics import torch_dataset

    return torch_dataset


def test_targets_in_torchvision_formats(tmp_path, torch, torch_dataset):
    SynthuaDataset, collate = torch_dataset.SynthuaDataset, torch_dataset.collate
    root = tiny_dataset.write(tmp_path / "ds")
    ds = SynthuaDataset(root)
    assert len(ds) == 2                                        # image 3 was rejected by QA
    image, target = ds[0]
    assert image.shape == (3, 6, 8) and image.dtype == torch.float32 and 0 <= image.min() <= image.max() <= 1
    rgb = np.array(Image.open(root / "images" / "train" / f"{tiny_dataset.NAMES[0]}.png"))
    assert torch.equal(image, torch.from_numpy(rgb.transpose(2, 0, 1)).float() / 255)
    # building rows 0-2 cols 0-3, person row 3 cols 0-1, wheelchair row 3 cols 2-4 (XYXY pixel edges)
    assert target["boxes"].dtype == torch.float32
    assert target["boxes"].tolist() == [[0, 0, 4, 3], [0, 3, 2, 4], [2, 3, 5, 4]]
    assert target["labels"].dtype == torch.int64
    assert target["labels"].tolist() == [tiny_dataset.BUILDING, tiny_dataset.PERSON, tiny_dataset.WHEELCHAIR]
    assert target["masks"].shape == (3, 6, 8) and target["masks"].dtype == torch.uint8
    cls, inst = tiny_dataset.label_maps()[0]
    for k in range(3):
        assert np.array_equal(target["masks"][k].numpy(), (inst == k + 1).astype(np.uint8))
    assert target["area"].tolist() == [12.0, 2.0, 3.0] and target["iscrowd"].tolist() == [0, 0, 0]
    assert target["semantic"].dtype == torch.int64 and np.array_equal(target["semantic"].numpy(), cls)
    assert target["image_id"] == 1
    assert len(SynthuaDataset(root, split="val")) == 1 and len(SynthuaDataset(root, split="test")) == 0
    images, targets = collate([ds[0], ds[1]])
    assert len(images) == 2 and targets[1]["labels"].tolist() == [tiny_dataset.BUILDING] * 2 + [tiny_dataset.WALKER]


def test_masks_equal_the_generated_instance_maps(generated, torch_dataset):
    ds = torch_dataset.SynthuaDataset(generated)
    assert len(ds) > 0
    for i in range(min(len(ds), 3)):
        _, target = ds[i]
        record = json.loads((generated / "records" / f"{target['name']}.json").read_text())
        inst = np.array(Image.open(generated / "frames" / target["name"] / "instance.png"))
        things = [r for r in record["instances"] if r["isthing"] and r["area"] > 0]
        assert len(things) == len(target["labels"])
        for k, r in enumerate(things):
            expected = inst == r["id"]
            assert np.array_equal(target["masks"][k].numpy().astype(bool), expected), r["prim_path"]
            ys, xs = np.nonzero(expected)
            assert target["boxes"][k].tolist() == [xs.min(), ys.min(), xs.max() + 1, ys.max() + 1]


def test_the_readme_training_example_runs(generated, monkeypatch, torch):
    """The PyTorch example of docs/statistics.md, as written, on a generated dataset (64x48): it trains without error."""
    import re
    import sys

    from conftest import REPO

    readme = (REPO / "docs" / "statistics.md").read_text()
    section = readme[readme.index("**PyTorch**"):]
    code = re.search(r"```python\n(.*?)```", section, re.S).group(1)
    monkeypatch.chdir(REPO)
    monkeypatch.setattr(sys, "path", list(sys.path))        # the example puts tools/ on it
    scope: dict = {}
    exec(code.replace('"out/dataset"', repr(str(generated))), scope)
    assert len(scope["data"]) > 0 and torch.isfinite(scope["loss"])
