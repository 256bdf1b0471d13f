#!/usr/bin/env python
"""Benchmark: denoised few-sample RGB against plain path tracing, scored against a high-spp reference.

Usage: python tools/bench_denoise.py [--scenario stages/district/scenario.usda] [--views CAM ...]
       [--time-code 24] [--large (1280x960; default 640x480)] [--reference-spp 512] [--spp 1 2 4 8]
       [--variant llvm_ad_rgb] [--cache out/bench_denoise] [--no-ablation] [--no-plain] [--save-images DIR]

Per view (default: CCTV_Largo, CCTV_AidUser_1, PedestrianEye_Street, UAV_Oblique of the district at time
code 24, under the stage's selected condition, as `synthua render` renders it) a reference is rendered at
--reference-spp with the box filter (the mean of each pixel's area, the quantity every setting estimates), as the
mean of two halves of --reference-spp / 2 samples with seeds 0 and 1000 (cached as EXR under --cache, keyed by view,
size, spp, seed and variant). Then every setting renders the same view (--no-plain leaves out the rows without
a denoiser):

  16 spp gaussian            the old default filter, no denoiser
  16 spp box                 no denoiser
  64 spp gaussian            the old default (64 spp, gaussian filter), no denoiser
  64 spp box                 no denoiser
  N spp box + OIDN           N in --spp: the firefly filter, then OIDN guided by albedo and normal
  N spp box + OIDN, no ff    (ablation, the default N only) the same without the firefly filter
  N spp gaussian + OIDN      (ablation, the default N only) OIDN on correlated noise

and is scored with synthua_usd.backends.image_quality (PSNR and SSIM on display values at the reference's exposure,
metered as rgb.png is: over the pixels whose label-pass ray sees a surface, not the sky or the void).
The reference's own noise caps every score: the ceiling printed per view is what a noise-free image would score,
from the difference of the two halves (synthua_usd.backends.image_quality.reference_ceiling_db).
Time is the RGB pass plus denoising (labels and scene loads left out; each setting renders one warm-up
frame first so kernel compilation is not counted). Other seeds than the reference's. Printed: one row per
view and setting, then per setting the mean PSNR, the minimum PSNR, the mean SSIM, the mean time and the
speed-up and PSNR difference against 16 spp gaussian (or the first row); the RenderConfig default is marked.
--save-images DIR writes, per view, the reference and, per denoised row, the pass before and after the denoiser
as sRGB PNGs at the exposure they are scored at (<view>_reference.png, <view>_<N>spp_noisy.png, ..._oidn.png).
Not a test: times depend on the machine and its load; compare ratios measured in the same run.
"""

from __future__ import annotations

import argparse
import hashlib
import math
import statistics
import sys
import time
from dataclasses import dataclass
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
VIEWS = ("/World/Cameras/CCTV_Largo", "/World/Cameras/CCTV_AidUser_1", "/World/Cameras/PedestrianEye_Street",
         "/World/Cameras/UAV_Oblique")


@dataclass(frozen=True)
class Setting:
    label: str
    spp: int
    pixel_filter: str
    denoise: bool
    fireflies: bool = True


def settings(spp_list, default_spp: int, ablation: bool, plain: bool = True) -> list[Setting]:
    rows = [Setting("16 spp gaussian", 16, "gaussian", False), Setting("16 spp box", 16, "box", False),
            Setting("64 spp gaussian (the old default)", 64, "gaussian", False),
            Setting("64 spp box", 64, "box", False)] if plain else []
    rows += [Setting(f"{n} spp box + OIDN", n, "box", True) for n in spp_list]
    if ablation:
        rows.append(Setting(f"{default_spp} spp box + OIDN, no firefly filter", default_spp, "box", True, False))
        rows.append(Setting(f"{default_spp} spp gaussian + OIDN", default_spp, "gaussian", True))
    return rows


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scenario", type=Path, default=REPO / "stages" / "district" / "scenario.usda")
    parser.add_argument("--views", nargs="+", default=list(VIEWS), help="camera prim paths")
    parser.add_argument("--time-code", type=float, default=24.0)
    parser.add_argument("--large", action="store_true", help="1280x960 instead of 640x480")
    parser.add_argument("--reference-spp", type=int, default=512)
    parser.add_argument("--spp", type=int, nargs="+", default=[1, 2, 4, 8], help="samples of the denoised rows")
    parser.add_argument("--variant", default=None)
    parser.add_argument("--cache", type=Path, default=REPO / "out" / "bench_denoise")
    parser.add_argument("--no-ablation", action="store_true", help="skip the firefly and gaussian ablation rows")
    parser.add_argument("--no-plain", action="store_true", help="skip the rows without a denoiser (16 and 64 spp)")
    parser.add_argument("--save-images", type=Path, default=None, metavar="DIR",
                        help="write the reference and each denoised row's pass before and after OIDN as PNGs")
    args = parser.parse_args()

    import numpy as np

    from synthua_usd.backends import denoise as denoise_module
    from synthua_usd.core import images
    from synthua_usd.backends.denoise import FireflyReport
    from synthua_usd.backends.image_quality import psnr_db, reference_ceiling_db, reference_scale, ssim
    from synthua_usd.backends.mitsuba.session import RenderSession
    from synthua_usd.model.render_config import RenderConfig
    from synthua_usd.model.taxonomy import ClassMap
    from synthua_usd.usd.cameras import read_camera
    from synthua_usd.usd.conditions import read_condition
    from synthua_usd.usd.reader import StageReader
    from synthua_usd.usd.stage_io import open_stage

    width, height = (1280, 960) if args.large else (640, 480)
    stage = open_stage(args.scenario)
    snapshot = StageReader(stage, ClassMap.default()).snapshot(args.time_code)
    condition = read_condition(stage, None)
    cameras = {path: read_camera(stage, path, args.time_code) for path in args.views}
    default = RenderConfig()
    print(f"{args.scenario.name} at {args.time_code:g}, {width}x{height}, reference {args.reference_spp} spp box "
          f"(two halves, seeds 0 and 1000), condition {condition.name if condition else None}; settings seed 1; "
          f"RenderConfig default: {default.spp} spp {default.pixel_filter}, denoise {default.denoise}")

    def render_all(config: RenderConfig, warm_up: bool, fireflies: bool = True) -> dict:
        """Per view: (frame, RGB + denoise seconds, the pass before the denoiser or None)."""
        session = RenderSession(config)
        real = denoise_module.suppress_fireflies
        real_pass = denoise_module.Denoiser.denoise_pass
        noisy = []
        if not fireflies:  # the ablation row: OIDN on the raw pass
            denoise_module.suppress_fireflies = lambda rgb: (rgb, FireflyReport(0, 0.0, 0.0))
        if args.save_images:  # keep the pass the denoiser is given
            def keeping(denoiser, color, albedo, normal):
                noisy.append(np.array(color))
                return real_pass(denoiser, color, albedo, normal)
            denoise_module.Denoiser.denoise_pass = keeping
        try:
            if warm_up:
                session.render(snapshot, cameras[args.views[0]], condition=condition)
            out = {}
            for path, camera in cameras.items():
                noisy.clear()
                frame = session.render(snapshot, camera, condition=condition)
                seconds = frame.seconds["rgb"] + frame.seconds.get("denoise", 0.0)
                out[path] = (frame, seconds, noisy[-1] if noisy else None)
            return out
        finally:
            denoise_module.suppress_fireflies = real
            denoise_module.Denoiser.denoise_pass = real_pass

    # The reference is the mean of two halves of --reference-spp / 2 samples with other seeds: their difference
    # says how much noise the reference itself has (image_quality.reference_ceiling_db).
    references, reference_halves, ceilings, scales = {}, {}, {}, {}
    variant = None
    half_spp = max(args.reference_spp // 2, 1)
    ref_session = None
    for path, camera in cameras.items():
        halves = []
        for seed in (0, 1000):
            key = hashlib.sha256(f"{args.scenario.resolve()}|{path}|{args.time_code}|{width}x{height}|"
                                 f"{half_spp}|{seed}|{args.variant}".encode()).hexdigest()[:16]
            cached = args.cache / f"ref_{path.rsplit('/', 1)[-1]}_{key}.exr"
            if cached.exists():
                halves.append(images.read_image(cached)[0].astype(np.float32))
                continue
            t0 = time.perf_counter()
            ref_session = ref_session or RenderSession(RenderConfig(
                width=width, height=height, spp=half_spp, pixel_filter="box", denoise=False, seed=0,
                variant=args.variant))
            frame = ref_session.render(snapshot, camera, condition=condition, seed=seed)
            halves.append(frame.rgb)
            cached.parent.mkdir(parents=True, exist_ok=True)
            images.write_linear_exr(cached, frame.rgb)
            print(f"reference half {path} (seed {seed}): {time.perf_counter() - t0:.0f} s ({frame.variant}) -> "
                  f"{cached}", flush=True)
        references[path] = (halves[0] + halves[1]) / 2
        reference_halves[path] = halves
    del ref_session

    rows = settings(args.spp, default.spp, not args.no_ablation, not args.no_plain)
    results: dict[str, list] = {}
    print(f"\n{'view':34} {'setting':44} {'PSNR dB':>8} {'SSIM':>7} {'time s':>7} {'fireflies':>9}")
    for row in rows:
        config = RenderConfig(width=width, height=height, spp=row.spp, pixel_filter=row.pixel_filter,
                              denoise=row.denoise, seed=1, variant=args.variant)
        rendered = render_all(config, warm_up=True, fireflies=row.fireflies)
        for path, (frame, seconds, before) in rendered.items():
            variant = frame.variant
            if path not in scales:  # the reference's exposure, metered as rgb.png is: over the surface pixels
                scales[path] = reference_scale(references[path], frame.hits.mesh_index >= 0)
                ceilings[path] = reference_ceiling_db(*reference_halves[path], scales[path])
            scale = scales[path]
            if args.save_images and before is not None:
                name = path.rsplit("/", 1)[-1]
                args.save_images.mkdir(parents=True, exist_ok=True)
                if not (args.save_images / f"{name}_reference.png").exists():
                    images.write_display_png(args.save_images / f"{name}_reference.png", references[path] * scale)
                images.write_display_png(args.save_images / f"{name}_{row.spp}spp_noisy.png", before * scale)
                images.write_display_png(args.save_images / f"{name}_{row.spp}spp_oidn.png", frame.rgb * scale)
            p = psnr_db(frame.rgb, references[path], scale)
            s = ssim(frame.rgb, references[path], scale)
            ff = frame.denoised["firefly_pixels"] if frame.denoised else ""
            results.setdefault(row.label, []).append((p, s, seconds))
            print(f"{path.rsplit('/', 1)[-1]:34} {row.label:44} {p:8.2f} {s:7.4f} {seconds:7.2f} {ff!s:>9}",
                  flush=True)

    print("\nreference noise ceiling (what a noise-free image would score, from the two halves), per view: "
          + ", ".join(f"{path.rsplit('/', 1)[-1]} {c:.1f} dB" for path, c in ceilings.items()))
    base_label = "16 spp gaussian" if "16 spp gaussian" in results else rows[0].label
    base = results[base_label]
    base_time = statistics.mean(r[2] for r in base)
    base_psnr = statistics.mean(r[0] for r in base)
    print(f"\nsummary over {len(cameras)} views ({variant}, {width}x{height}, reference {args.reference_spp} spp):")
    print(f"{'setting':44} {'mean PSNR':>9} {'min PSNR':>8} {'mean SSIM':>9} {'mean s':>7} {'speed-up':>8} "
          f"{'dPSNR':>6}")
    for row in rows:
        r = results[row.label]
        mean_time = statistics.mean(x[2] for x in r)
        mark = "  <- default" if (row.spp, row.pixel_filter, row.denoise, row.fireflies) == (
            default.spp, default.pixel_filter, default.denoise, True) else ""
        print(f"{row.label:44} {statistics.mean(x[0] for x in r):9.2f} {min(x[0] for x in r):8.2f} "
              f"{statistics.mean(x[1] for x in r):9.4f} {mean_time:7.2f} {base_time / mean_time:7.1f}x "
              f"{statistics.mean(x[0] for x in r) - base_psnr:+6.2f}{mark}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
