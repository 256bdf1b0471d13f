#!/usr/bin/env python
"""Benchmark: the per-image annotation phase of a dataset worker, alone, on one captured frame.

Usage:
  python tools/bench_annotation.py --capture FRAME.pkl [--scenario stages/district/scenario.usda]
         [--camera /World/Cameras/CCTV_Largo] [--time-code 24] [--width 1280 --height 960] [--spp 1]
  python tools/bench_annotation.py FRAME.pkl [--repeat 5] [--profile]

``--capture`` renders one image through :func:`synthua_usd.pipeline.dataset_worker.render_image` (a real
worker: stage, render session, amodal traces; the district's largo at 1280x960 by default) and pickles what
the render and the amodal traces handed over (snapshot, camera, rendered buffers, amodal pixel sets) with the
worker's job and the planned image.

The default mode runs ``render_image`` again ``--repeat`` times on that frame, the session and the stage
reader replaced by the captured results, so that what remains is the annotation phase (truncation, COCO
instances and keypoints, panoptic, Cityscapes arrays, previews, QA, YOLO lines, the record): it prints the
CPU seconds (``resource.getrusage``, this process) and wall seconds per image, best and median, and the
record's digest, so two code versions can be compared on the same frame (run it with ``PYTHONPATH`` set to
each checkout, one after the other). ``--profile`` adds a cProfile of one more run. Not a test.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import pickle
import resource
import statistics
import sys
import time
from pathlib import Path
from types import SimpleNamespace

REPO = Path(__file__).resolve().parents[1]


def capture(args) -> None:
    from synthua_usd.dataset.config import GenerationConfig
    from synthua_usd.dataset.formats import yolo
    from synthua_usd.dataset.sampling import PlannedImage
    from synthua_usd.model.render_config import RenderConfig
    from synthua_usd.model.taxonomy import ClassMap
    from synthua_usd.pipeline import dataset_worker

    class_map = ClassMap.default()
    document = json.loads((REPO / "configs" / "district.json").read_text())
    document["qa"]["reject"] = []  # as tools/bench_targets.py: every image accepted or flagged, all files made
    config = GenerationConfig.from_document(document)
    render = RenderConfig(width=args.width, height=args.height, spp=args.spp, max_depth=4, pixel_filter="box",
                          denoise=False)
    job = dataset_worker.WorkerJob(scenario=str(Path(args.scenario).resolve()), out_dir="/nonexistent",
                                   render=render, config=config, class_map_document=class_map.document(),
                                   camera_index={args.camera: 0}, yolo_classes=yolo.class_index(class_map))
    planned = PlannedImage(camera_path=args.camera, camera_name=args.camera.rsplit("/", 1)[-1], rig_type="cctv",
                           time_code=float(args.time_code), condition=None, seed=0, id=1)
    state = dataset_worker.init_worker(job)
    got = {}
    reader_snapshot, session_render, session_amodal = (state.reader.snapshot, state.session.render,
                                                      state.session.amodal)

    def keep(name, fn):
        def wrapped(*a, **k):
            got[name] = fn(*a, **k)
            return got[name]
        return wrapped

    state.reader.snapshot = keep("snapshot", reader_snapshot)
    state.session.render = keep("rendered", session_render)
    state.session.amodal = keep("amodal", session_amodal)
    t0 = time.perf_counter()
    image = dataset_worker.render_image(state, planned)
    print(f"rendered in {time.perf_counter() - t0:.1f} s; seconds {image.seconds}")
    rendered = got["rendered"]
    # what render_image reads of the render result, as plain data
    plain = SimpleNamespace(rgb=rendered.rgb, class_ids=rendered.class_ids, instance_ids=rendered.instance_ids,
                            hits=SimpleNamespace(z_m=rendered.hits.z_m), exposure=rendered.exposure,
                            seconds=dict(rendered.seconds), variant=rendered.variant, denoised=rendered.denoised)
    from synthua_usd.usd.cameras import read_camera

    camera = read_camera(state.stage, planned.camera_path, planned.time_code)
    with open(args.frame, "wb") as f:
        pickle.dump({"job": job, "planned": planned, "snapshot": got["snapshot"], "camera": camera,
                     "rendered": plain, "amodal": got.get("amodal", {}), "condition": state.condition(None)}, f)
    print(f"wrote {args.frame}")


class _Replay:
    """The parts of a worker's state ``render_image`` uses, answering with the captured frame."""

    def __init__(self, frame: dict) -> None:
        from synthua_usd.model.taxonomy import ClassMap

        self.job = frame["job"]
        self.class_map = ClassMap.from_document(self.job.class_map_document, source="class_map.json")
        self.stage = None
        self.reader = SimpleNamespace(snapshot=lambda time_code: frame["snapshot"])
        self.session = SimpleNamespace(render=lambda *a, **k: frame["rendered"],
                                       amodal=lambda *a, **k: frame["amodal"])
        self._condition = frame["condition"]

    def condition(self, name):
        return self._condition


def replay(args) -> None:
    from synthua_usd.pipeline import dataset_worker
    from synthua_usd.usd import cameras

    with open(args.frame, "rb") as f:
        frame = pickle.load(f)
    cameras.read_camera = lambda stage, path, time_code: frame["camera"]
    state = _Replay(frame)

    def once():
        r0, t0 = resource.getrusage(resource.RUSAGE_SELF), time.perf_counter()
        image = dataset_worker.render_image(state, frame["planned"])
        r1, t1 = resource.getrusage(resource.RUSAGE_SELF), time.perf_counter()
        return image, (r1.ru_utime + r1.ru_stime) - (r0.ru_utime + r0.ru_stime), t1 - t0

    image, _, _ = once()  # warm-up (imports, caches)
    cpu, wall = [], []
    for _ in range(args.repeat):
        image, c, w = once()
        cpu.append(c)
        wall.append(w)
    digest = hashlib.sha256(json.dumps(image.record, sort_keys=True).encode()).hexdigest()[:16]
    arrays = hashlib.sha256()
    for key in sorted(image.arrays):
        value = image.arrays[key]
        arrays.update(key.encode())
        arrays.update(value.encode() if isinstance(value, str) else value.tobytes())
    print(f"instances {len(image.record['instances'])}  cpu s/image best {min(cpu):.3f} median "
          f"{statistics.median(cpu):.3f}  wall best {min(wall):.3f} median {statistics.median(wall):.3f}  "
          f"record {digest}  arrays {arrays.hexdigest()[:16]}")
    if args.profile:
        import cProfile
        import pstats

        profile = cProfile.Profile()
        profile.runcall(dataset_worker.render_image, state, frame["planned"])
        pstats.Stats(profile, stream=sys.stdout).sort_stats("cumulative").print_stats(35)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("frame", help="pickle of the captured frame (written with --capture, read otherwise)")
    parser.add_argument("--capture", action="store_true")
    parser.add_argument("--scenario", default=str(REPO / "stages" / "district" / "scenario.usda"))
    parser.add_argument("--camera", default="/World/Cameras/CCTV_Largo")
    parser.add_argument("--time-code", type=float, default=24.0)
    parser.add_argument("--width", type=int, default=1280)
    parser.add_argument("--height", type=int, default=960)
    parser.add_argument("--spp", type=int, default=1)
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--profile", action="store_true")
    args = parser.parse_args(argv)
    capture(args) if args.capture else replay(args)
    return 0


if __name__ == "__main__":
    sys.exit(main())
