"""Regenerate the RGB reference images of the tests: ``make refs``.

Renders the tiny reference scene (tests/reference_images.py owns the scene, size, samples and seed) once
per Mitsuba variant of the test fixtures and writes ``tests/data/refs/tiny_<variant>.exr``. Run it only
when a change of the rendered images is intended, and say why in the commit that updates the files.
A variant that cannot run here is left as it is.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

TESTS = Path(__file__).resolve().parents[1] / "tests"
sys.path.insert(0, str(TESTS))

from conftest import MITSUBA_VARIANTS  # noqa: E402  (tests/ is put on the path above)
from reference_images import REF_SEED, REF_SPP, reference_path, render_reference, tiny_scene  # noqa: E402
from synthua_usd.core import images  # noqa: E402
from synthua_usd.backends.mitsuba import variants  # noqa: E402
from synthua_usd.core.errors import InputError  # noqa: E402


def main() -> int:
    snapshot, camera = tiny_scene()
    written = 0
    for name in MITSUBA_VARIANTS:
        try:
            variants.activate(name)
        except InputError as exc:
            print(f"make_refs: skipping {name}: {exc}", file=sys.stderr)
            continue
        path = reference_path(name)
        rgb = render_reference(snapshot, camera, name)
        written += 1
        # The EXR header holds a time stamp: leave a file whose pixels did not change alone.
        if path.exists() and np.array_equal(images.read_image(path)[0], rgb):
            print(f"{path.relative_to(TESTS.parent)} is unchanged")
            continue
        path.parent.mkdir(parents=True, exist_ok=True)
        images.write_linear_exr(path, rgb)
        print(f"wrote {path.relative_to(TESTS.parent)} ({REF_SPP} spp, seed {REF_SEED}, {path.stat().st_size} bytes)")
    return 0 if written else 1


if __name__ == "__main__":
    sys.exit(main())
