"""Resource checks made before allocating: how much memory a job will need against what the machine has.

Estimates are deliberately generous (they count the temporary arrays of the label pass and the RGB
accumulation), so a job that passes does not run the machine out of memory halfway.
"""

from __future__ import annotations

import os

from synthua_usd.core.errors import InputError

#: Bytes one pixel costs while a frame renders: label rays and hits (about 160 B with numpy's temporaries),
#: the RGB film, its float64 accumulation and the float32 image (about 100 B), encoding the files (40 B).
FRAME_BYTES_PER_PIXEL = 300
#: Share of the available memory a job may plan to use.
MEMORY_SHARE = 0.8


def available_memory_bytes() -> int:
    """MemAvailable from /proc/meminfo (Linux), else the physical memory."""
    try:
        with open("/proc/meminfo", encoding="ascii") as f:
            for line in f:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except OSError:
        pass
    return os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")


def check_memory(needed_bytes: float, what: str, hint: str) -> None:
    """Refuse a job whose estimate exceeds :data:`MEMORY_SHARE` of the available memory."""
    budget = MEMORY_SHARE * available_memory_bytes()
    if needed_bytes > budget:
        raise InputError(f"{what}: needs about {needed_bytes / 2**30:.1f} GiB of memory, more than the "
                         f"{budget / 2**30:.1f} GiB available; expected {hint}")


def check_frame_memory(width: int, height: int) -> None:
    """A width x height frame fits in memory."""
    check_memory(float(width) * height * FRAME_BYTES_PER_PIXEL, f"image size {width}x{height}",
                 "a smaller --width/--height")
