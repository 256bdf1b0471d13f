#!/usr/bin/env python
"""Training pilot (a benchmark, not a test): does the data teach a model? A small reproduction of the
paper's pilot (Section 3.9), on CPU, in bounded time.

1. Generates two datasets of the demo street from ``configs/demo.json`` (``synthua generate``, resumed or
   reused when already there): *train* at the odd time codes 1, 3, ..., 47 with render seeds 0 and 1, and
   *held-out* at time codes 2, 6, ..., 46 with seed 2 (other frames and other noise; the street has three
   cameras, so held-out frames come from the same cameras).
2. Trains a small U-Net, written here in plain PyTorch (no torchvision), from scratch on the train images'
   class maps: cross-entropy with unlabelled pixels void and square-root inverse-frequency class weights,
   Adam, random 120x160 crops (one place per batch) and horizontal flips, for ``--minutes`` of wall time
   (default 12) on ``--threads`` threads; predictions are full-size.
3. Predicts the held-out images as class-id PNGs and scores them with ``synthua eval`` (the CLI, run as a
   user would), then writes a table of per-class IoU, precision, recall and F1 (mobility-aid classes
   marked) with the run's settings to ``WORK/pilot_results.md`` and, with ``--table``, to another path.

Usage:
  nice -n 10 python tools/pilot_segmentation.py [--work out/pilot] [--minutes 12] [--threads 2]
         [--table docs/measured/pilot_segmentation.md]
"""

from __future__ import annotations

import argparse
import copy
import json
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
SCENARIO = REPO / "stages" / "scenario.usda"


def pilot_configs(base: dict) -> dict[str, dict]:
    """The two generation configs derived from ``configs/demo.json``: train and held-out (see module)."""
    base = {k: v for k, v in base.items() if k != "$schema"}
    train = copy.deepcopy(base) | {"name": "pilot-train", "images": 150, "time_codes": "1:47:2", "seeds": [0, 1],
                                   "split": {"train": 1.0, "val": 0.0, "test": 0.0, "seed": 0}}
    heldout = copy.deepcopy(base) | {"name": "pilot-heldout", "images": 36, "time_codes": "2:48:4", "seeds": [2],
                                     "split": {"train": 0.0, "val": 0.0, "test": 1.0, "seed": 0}}
    return {"train": train, "heldout": heldout}


def synthua(*args: str) -> str:
    """Run the ``synthua`` CLI of this checkout; its stdout, or exit with its one-line error."""
    env = dict(os.environ, PYTHONPATH=str(REPO) + os.pathsep + os.environ.get("PYTHONPATH", ""))
    done = subprocess.run([sys.executable, "-m", "synthua_usd", *args], capture_output=True, text=True, env=env)
    if done.returncode != 0:
        sys.exit(f"synthua {' '.join(args)} failed ({done.returncode}): {done.stderr.strip()[-500:]}")
    return done.stdout


def build_unet(classes: int, width: int = 16):
    """A three-level U-Net (conv-BN-ReLU pairs, max-pool down, transposed-conv up, skip concatenations):
    (B, 3, H, W) -> (B, classes, H, W) logits for H, W divisible by 8."""
    import torch
    from torch import nn

    def block(i, o):
        return nn.Sequential(nn.Conv2d(i, o, 3, padding=1, bias=False), nn.BatchNorm2d(o), nn.ReLU(inplace=True),
                             nn.Conv2d(o, o, 3, padding=1, bias=False), nn.BatchNorm2d(o), nn.ReLU(inplace=True))

    class UNet(nn.Module):
        def __init__(self):
            super().__init__()
            w = width
            self.e1, self.e2, self.e3, self.mid = block(3, w), block(w, 2 * w), block(2 * w, 4 * w), block(4 * w, 8 * w)
            self.u3, self.d3 = nn.ConvTranspose2d(8 * w, 4 * w, 2, 2), block(8 * w, 4 * w)
            self.u2, self.d2 = nn.ConvTranspose2d(4 * w, 2 * w, 2, 2), block(4 * w, 2 * w)
            self.u1, self.d1 = nn.ConvTranspose2d(2 * w, w, 2, 2), block(2 * w, w)
            self.head = nn.Conv2d(w, classes, 1)
            self.pool = nn.MaxPool2d(2)

        def forward(self, x):
            e1 = self.e1(x)
            e2 = self.e2(self.pool(e1))
            e3 = self.e3(self.pool(e2))
            m = self.mid(self.pool(e3))
            d3 = self.d3(torch.cat([self.u3(m), e3], 1))
            d2 = self.d2(torch.cat([self.u2(d3), e2], 1))
            d1 = self.d1(torch.cat([self.u1(d2), e1], 1))
            return self.head(d1)

    return UNet()


def load_tensors(root: Path):
    """(images (N, 3, H, W) float32, semantic (N, H, W) int64, names) of every image of the dataset."""
    import torch

    from synthua_usd.analytics.torch_dataset import SynthuaDataset

    ds = SynthuaDataset(root)
    items = [ds[i] for i in range(len(ds))]
    return (torch.stack([im for im, _ in items]), torch.stack([t["semantic"] for _, t in items]),
            [t["name"] for _, t in items])


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--work", type=Path, default=REPO / "out" / "pilot")
    ap.add_argument("--minutes", type=float, default=12.0, help="Training wall time (default 12).")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--batch", type=int, default=8)
    ap.add_argument("--crop", type=int, nargs=2, default=(120, 160), metavar=("H", "W"),
                    help="Random training crop, multiples of 8 (default 120 160); predictions are full-size.")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--table", type=Path, help="Also write the results table here (markdown).")
    args = ap.parse_args()

    import torch

    from synthua_usd.analytics.dataset_index import load_index
    from synthua_usd.analytics.statistics import compute, mobility_aid_classes
    from synthua_usd.core.images import write_id_png

    torch.manual_seed(args.seed)
    torch.set_num_threads(args.threads)
    work = args.work
    (work / "configs").mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    for key, cfg in pilot_configs(json.loads((REPO / "configs" / "demo.json").read_text())).items():
        path = work / "configs" / f"{key}.json"
        path.write_text(json.dumps(cfg, indent=2) + "\n")
        print(synthua("generate", str(SCENARIO), "--config", str(path), "--out", str(work / key)).strip(), flush=True)
    t_generate = time.perf_counter() - t0

    index = load_index(work / "train")
    class_map = index.class_map
    k = max(c.id for c in class_map.classes) + 1
    pixels = np.zeros(k)
    for c in compute(index).classes:
        pixels[c.id] = c.pixels
    freq = pixels / pixels.sum()
    weights = np.where(freq > 0, 1.0 / np.sqrt(np.maximum(freq, 1e-12)), 0.0)
    weights /= weights[freq > 0].mean()
    images, labels, _ = load_tensors(work / "train")
    model = build_unet(k)
    optimiser = torch.optim.Adam(model.parameters(), lr=2e-3)
    loss_fn = torch.nn.CrossEntropyLoss(weight=torch.tensor(weights, dtype=torch.float32), ignore_index=0)
    rng = np.random.default_rng(args.seed)
    t1 = time.perf_counter()
    steps, epochs, losses = 0, 0, []
    model.train()
    while time.perf_counter() - t1 < args.minutes * 60:
        order = rng.permutation(len(images))
        for start in range(0, len(order) - args.batch + 1, args.batch):
            idx = torch.from_numpy(order[start:start + args.batch])
            top = int(rng.integers(0, images.shape[2] - args.crop[0] + 1))
            left = int(rng.integers(0, images.shape[3] - args.crop[1] + 1))
            rows, cols = slice(top, top + args.crop[0]), slice(left, left + args.crop[1])
            x, y = images[idx][:, :, rows, cols], labels[idx][:, rows, cols]
            flip = torch.from_numpy(rng.random(len(idx)) < 0.5)
            x[flip], y[flip] = x[flip].flip(-1), y[flip].flip(-1)
            loss = loss_fn(model(x), y)
            optimiser.zero_grad()
            loss.backward()
            optimiser.step()
            losses.append(loss.item())
            steps += 1
            if time.perf_counter() - t1 >= args.minutes * 60:
                break
        epochs += 1
        print(f"epoch {epochs}: {steps} steps, mean loss of the last 20 {np.mean(losses[-20:]):.3f}, "
              f"{(time.perf_counter() - t1) / 60:.1f} min", flush=True)
    t_train = time.perf_counter() - t1

    held_images, _, held_names = load_tensors(work / "heldout")
    pred_dir = work / "predictions"
    pred_dir.mkdir(exist_ok=True)
    model.eval()
    with torch.no_grad():
        for i in range(0, len(held_images), 8):
            logits = model(held_images[i:i + 8])
            logits[:, 0] = -torch.inf          # unlabelled is void: never predicted
            for name, pred in zip(held_names[i:i + 8], logits.argmax(1).numpy().astype(np.uint8)):
                write_id_png(pred_dir / f"{name}.png", pred)
    eval_dir = work / "eval"
    print(synthua("eval", "--gt", str(work / "heldout"), "--pred", str(pred_dir), "--out", str(eval_dir)), flush=True)
    result = json.loads((eval_dir / "metrics.json").read_text())
    aids = {c.name for c in mobility_aid_classes(class_map.classes)}
    s = result["summary"]
    train_cfg, held_cfg = pilot_configs(json.loads((REPO / "configs" / "demo.json").read_text())).values()

    def pct(v):
        return "–" if v is None else f"{100 * v:.1f}"

    lines = [
        "# Training pilot: a small U-Net on the demo street (tools/pilot_segmentation.py)",
        "",
        f"Train: {len(images)} images of the demo street (time codes {train_cfg['time_codes']}, seeds "
        f"{train_cfg['seeds']}, conditions {', '.join(train_cfg['conditions'])}, "
        f"{images.shape[3]}x{images.shape[2]}); held out: {len(held_images)} images at time codes "
        f"{held_cfg['time_codes']}, seed {held_cfg['seeds'][0]} (same three cameras). Model: a 3-level U-Net (width 16, "
        f"{sum(p.numel() for p in model.parameters()):,} parameters), plain PyTorch {torch.__version__}, from scratch; "
        f"weighted cross-entropy (unlabelled void), Adam 2e-3, batches of {args.batch} random {args.crop[0]}x{args.crop[1]} "
        f"crops, flips; full-size predictions; {steps} steps "
        f"({epochs} epochs) in {t_train / 60:.1f} min on {args.threads} CPU threads; final loss "
        f"{np.mean(losses[-20:]):.3f}. Datasets generated or reused in {t_generate / 60:.1f} min.",
        "",
        f"Held-out, `synthua eval` (unlabelled pixels void): pixel accuracy {pct(s['pixel_accuracy'])} %, mean IoU "
        f"{pct(s['mean_iou'])} % over {s['mean_iou_classes']} classes, frequency-weighted IoU "
        f"{pct(s['frequency_weighted_iou'])} %.",
        "",
        "| class | held-out gt pixels | IoU % | precision % | recall % | F1 % | accuracy % |",
        "|---|---|---|---|---|---|---|"]
    for row in result["classes"]:
        if row["id"] == 0 or (row["gt_pixels"] == 0 and row["pred_pixels"] == 0):
            continue
        name = f"**{row['name']}** (mobility aid)" if row["name"] in aids else row["name"]
        lines.append(f"| {name} | {row['gt_pixels']:,} | {pct(row['iou'])} | {pct(row['precision'])} | "
                     f"{pct(row['recall'])} | {pct(row['f1'])} | {pct(row['accuracy'])} |")
    absent = sorted(a for a in aids if not any(r["name"] == a and r["gt_pixels"] for r in result["classes"]))
    lines += ["", f"Mobility-aid classes without held-out pixels (the demo street's agents use none of them): "
              f"{', '.join(absent) or 'none'}."]
    text = "\n".join(lines) + "\n"
    (work / "pilot_results.md").write_text(text)
    if args.table:
        args.table.parent.mkdir(parents=True, exist_ok=True)
        args.table.write_text(text)
    print(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
