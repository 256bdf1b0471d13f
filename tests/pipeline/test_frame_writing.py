"""``synthua render`` with several frames writes frame N while frame N+1 renders; a failed write is one line
and leaves earlier results as they were."""

from __future__ import annotations

import errno
import threading
import time

from conftest import DATA
from hostile import tree_state
from synthua_usd.backends.mitsuba.session import RenderSession
from synthua_usd.pipeline import frame as frame_module
from synthua_usd.pipeline.frame import FrameRequest, run_frames

STAGE = DATA / "valid" / "tiny_scene.usda"  # time codes 1 and 2, camera /World/Cam
CAMERA = "/World/Cam"


def _record_events(monkeypatch, fail_on: int | None = None, write_seconds: float = 0.4) -> list:
    """Wrap the session's render and the frame writer so that they log (event, frame index, time)."""
    events, lock = [], threading.Lock()
    real_render, real_write = RenderSession.render, frame_module.write_frame
    counter = {"render": 0, "write": 0}

    def log(name, key):
        with lock:
            events.append((name, counter[key], time.perf_counter()))

    def render(self, *args, **kwargs):
        log("render start", "render")
        try:
            return real_render(self, *args, **kwargs)
        finally:
            log("render end", "render")
            counter["render"] += 1

    def write(*args, **kwargs):
        log("write start", "write")
        time.sleep(write_seconds)  # a slow disk
        if fail_on == counter["write"]:
            raise OSError(errno.ENOSPC, "No space left on device", str(args[0] / "rgb.exr"))
        try:
            return real_write(*args, **kwargs)
        finally:
            log("write end", "write")
            counter["write"] += 1

    monkeypatch.setattr(RenderSession, "render", render)
    monkeypatch.setattr(frame_module, "write_frame", write)
    return events


def test_frame_n_is_written_while_frame_n_plus_1_renders(monkeypatch, tmp_path):
    events = _record_events(monkeypatch)
    run = run_frames(FrameRequest(stage_path=STAGE, out_dir=tmp_path / "out", camera_paths=(CAMERA,),
                                  time_codes=(1, 2, 1.5), width=16, height=12, spp=1))
    at = {(name, i): t for name, i, t in events}
    for n in (0, 1):
        # The next render starts before this frame's files are written: the loop did not wait for them.
        assert at[("render start", n + 1)] < at[("write end", n)], events
        assert at[("write start", n)] >= at[("render end", n)]
    # Bounded: frame N+2 does not render before frame N is written (one frame waits at most).
    assert at[("render start", 2)] >= at[("write end", 0)]
    assert [f.out_dir.name for f in run.frames] == ["0001", "0002", "0001.500"]
    for frame in run.frames:
        assert frame.files and all(p.is_file() for p in frame.files)


def test_a_failed_background_write_is_one_line_and_keeps_earlier_results(monkeypatch, tmp_path, run_cli):
    out = tmp_path / "out"
    assert run_cli("render", STAGE, "--camera", CAMERA, "--time-code", "1,2", "--width", "16", "--height", "12",
                   "--spp", "1", "--out", out)[0] == 0
    before, around = tree_state(out), sorted(p.name for p in tmp_path.iterdir())
    _record_events(monkeypatch, fail_on=1, write_seconds=0.05)
    code, _, err = run_cli("render", STAGE, "--camera", CAMERA, "--time-code", "1,2", "--width", "24", "--height",
                           "18", "--spp", "1", "--seed", "7", "--out", out)
    lines = [line for line in err.splitlines() if line.strip()]
    assert code == 2 and "Traceback" not in err, err
    assert len([line for line in lines if "error:" in line]) == 1 and lines[-1].startswith("synthua: error: "), err
    assert "no space left on device" in lines[-1].lower() and "rgb.exr" in lines[-1], lines[-1]
    assert tree_state(out) == before  # the first frame's new files were staged, never moved into place
    assert sorted(p.name for p in tmp_path.iterdir()) == around  # and the staging folder is gone
