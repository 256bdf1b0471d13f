"""Preview videos of tracking sequences: the frames with every track's box and id drawn, as an MP4.

Encoded with PyAV (FFmpeg's libraries in the PyPI wheel; no system ffmpeg): H.264 (libx264) at CRF 23 in one
thread, so the same frames give the same bytes; boxes and ids drawn with Pillow's bundled font. A track keeps one
colour through the sequence (its id's hash), a person and the device it uses the same colour.
"""

from __future__ import annotations

import zlib
from pathlib import Path

import numpy as np

from synthua_usd.core.atomic import atomic_path

CODEC = "libx264"


def track_colour(track_id: int) -> tuple[int, int, int]:
    """A bright colour for ``track_id``, the same in every frame and run."""
    h = zlib.crc32(str(int(track_id)).encode())
    rgb = np.array([(h >> 0) & 255, (h >> 8) & 255, (h >> 16) & 255], float)
    return tuple(int(v) for v in 80 + rgb * (175 / 255))


def draw_boxes(rgb8: np.ndarray, boxes: list[tuple[int, int, int, int, int, str]]) -> np.ndarray:
    """``rgb8`` (H, W, 3) uint8 with each ``(x, y, w, h, colour id, label)`` box (pixel edges, from the top-left)
    outlined in the colour of its colour id and labelled above its top-left corner."""
    from PIL import Image, ImageDraw, ImageFont

    image = Image.fromarray(np.ascontiguousarray(rgb8, np.uint8))
    draw = ImageDraw.Draw(image)
    font = ImageFont.load_default()
    for x, y, w, h, colour_id, label in boxes:
        colour = track_colour(colour_id)
        draw.rectangle([x, y, x + max(w, 1) - 1, y + max(h, 1) - 1], outline=colour, width=2)
        draw.text((x + 2, max(0, y - 11)), label, fill=colour, font=font)
    return np.asarray(image)


def write_preview(path: Path, frames, fps: float) -> Path:
    """Encode ``frames`` (an iterable of (H, W, 3) uint8 images of one size) at ``fps`` into the MP4 ``path``
    (atomically)."""
    import av

    from fractions import Fraction

    path = Path(path)
    with atomic_path(path) as tmp:
        with av.open(str(tmp), mode="w", format="mp4") as container:
            stream = None
            for image in frames:
                if stream is None:
                    stream = container.add_stream(CODEC, rate=Fraction(fps).limit_denominator(1000))
                    stream.height, stream.width = (image.shape[0] // 2) * 2, (image.shape[1] // 2) * 2
                    stream.pix_fmt = "yuv420p"
                    stream.thread_count = 1
                    stream.options = {"crf": "23"}
                frame = av.VideoFrame.from_ndarray(
                    np.ascontiguousarray(image[:stream.height, :stream.width]), format="rgb24")
                for packet in stream.encode(frame):
                    container.mux(packet)
            if stream is not None:
                for packet in stream.encode():
                    container.mux(packet)
    return path
