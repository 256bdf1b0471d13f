#!/usr/bin/env python
"""The figure of docs/compositing.md's camera model: a side view of the camera over the ground plane and the image
it forms, two people of one height at two distances.

Usage: python tools/composite_camera_figure.py [--out docs/images/composite_camera_model.png]

Drawn from :class:`synthua_usd.model.photo_camera.PhotoCamera` itself (rows, sizes and angles are the model's).
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=REPO / "docs" / "images" / "composite_camera_model.png")
    args = parser.parse_args()

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from synthua_usd.model.photo_camera import PhotoCamera

    width, height, f, cam_h, person_h = 640, 480, 560.0, 1.5, 1.3
    camera = PhotoCamera(width, height, 150.0, cam_h, f)
    near, far = 4.0, 10.0
    fig, (side, image) = plt.subplots(1, 2, figsize=(11, 4.2), gridspec_kw={"width_ratios": [1.35, 1]})

    side.axhline(0, color="0.35", lw=2)
    side.plot([0], [cam_h], "ks", ms=9)
    side.annotate("camera", (0, cam_h), (0.15, cam_h + 0.25))
    side.annotate("", (0, 0), (0, cam_h), arrowprops={"arrowstyle": "<->", "color": "C0"})
    side.text(-0.55, cam_h / 2, "H", color="C0", fontsize=13)
    side.plot([0, 13], [cam_h, cam_h], ":", color="0.5")
    side.text(11.2, cam_h + 0.08, "to the horizon", color="0.4", fontsize=9)
    for z, colour in ((near, "C3"), (far, "C2")):
        side.plot([z, z], [0, person_h], color=colour, lw=6, solid_capstyle="butt")
        side.plot([0, z], [cam_h, 0], color=colour, lw=1)
        side.plot([0, z], [cam_h, person_h], color=colour, lw=1, ls="--")
        elev = math.degrees(math.atan2(cam_h, z))
        side.text(z + 0.15, 0.2, f"Z = {z:g} m\nelevation {elev:.0f}°", color=colour, fontsize=9)
    side.text(near / 2 - 0.6, -0.3, "ground plane", color="0.35")
    side.set_xlim(-0.8, 13.2)
    side.set_ylim(-0.5, 2.4)
    side.set_aspect("equal")
    side.set_xlabel("ground distance, m")
    side.set_title("side view")

    image.set_xlim(0, width)
    image.set_ylim(height, 0)
    image.set_aspect("equal")
    image.axhline(camera.horizon_row_px, color="0.5", ls=":")
    image.text(8, camera.horizon_row_px - 8, "horizon row $y_h$", color="0.4", fontsize=9)
    for z, x, colour in ((near, 400, "C3"), (far, 200, "C2")):
        row = camera.horizon_row_px + f * cam_h / z
        pixels = camera.pixel_height(person_h, row)
        image.plot([x, x], [row, row - pixels], color=colour, lw=8, solid_capstyle="butt")
        image.plot([x - 30, x + 30], [row, row], color=colour, lw=1)
        image.text(x + 12, row + 22, f"$y_a$ = {row:.0f}: {pixels:.0f} px tall", color=colour, fontsize=9)
    image.set_title(f"the image ({width} x {height}, f = {f:.0f} px)")
    image.text(10, 470, "$Z = f H / (y_a - y_h)$,  height in px $= h (y_a - y_h) / H$", fontsize=10)
    fig.tight_layout()
    args.out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(args.out, dpi=110)
    print(f"wrote {args.out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
