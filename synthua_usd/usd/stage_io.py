"""Opening stages safely: missing and malformed files become one-line :class:`StageError` messages."""

from __future__ import annotations

from pathlib import Path

from pxr import Sdf, Tf, Usd, UsdGeom

from synthua_usd.errors import StageError

USD_SUFFIXES = (".usda", ".usdc", ".usd", ".usdz")


def _first_line(exc: Exception) -> str:
    text = str(exc).strip()
    # Tf errors carry "Error in '...' at line N in file ... : 'message'"; keep the message.
    for line in text.splitlines():
        if line.strip():
            text = line.strip()
            break
    return text


def open_layer(path: str | Path) -> Sdf.Layer:
    """Open one layer file (no composition)."""
    path = Path(path)
    _check_file(path)
    try:
        layer = Sdf.Layer.FindOrOpen(str(path))
    except Tf.ErrorException as exc:
        raise StageError(f"{path}: not a readable USD layer: {_first_line(exc)}") from None
    if layer is None:
        raise StageError(f"{path}: not a readable USD layer")
    return layer


def open_stage(path: str | Path) -> Usd.Stage:
    """Open and compose a stage with all payloads loaded.

    Raises :class:`StageError` naming the file when it is missing, not USD, or fails to parse.
    """
    path = Path(path)
    _check_file(path)
    try:
        stage = Usd.Stage.Open(str(path), Usd.Stage.LoadAll)
    except Tf.ErrorException as exc:
        raise StageError(f"{path}: not a readable USD stage: {_first_line(exc)}") from None
    if stage is None:
        raise StageError(f"{path}: not a readable USD stage")
    return stage


def _check_file(path: Path) -> None:
    if not path.exists():
        raise StageError(f"{path}: file not found")
    if not path.is_file():
        raise StageError(f"{path}: not a file")
    if path.suffix.lower() not in USD_SUFFIXES:
        raise StageError(f"{path}: unknown USD file extension '{path.suffix}'; expected one of {', '.join(USD_SUFFIXES)}")
    try:
        with path.open("rb"):
            pass
    except OSError as exc:
        raise StageError(f"{path}: cannot read ({exc.strerror})") from None


def time_range(stage: Usd.Stage) -> tuple[float, float] | None:
    """(start, end) time codes when the stage states them, else None (a static stage)."""
    if stage.HasAuthoredTimeCodeRange():
        return stage.GetStartTimeCode(), stage.GetEndTimeCode()
    return None


def check_time_code(stage: Usd.Stage, time_code: float) -> None:
    """Refuse a time code outside the stage's authored time range."""
    span = time_range(stage)
    if span is None:
        return
    start, end = span
    if not (start <= time_code <= end):
        raise StageError(f"{stage.GetRootLayer().identifier}: time code {time_code:g} is outside the stage's time range "
                         f"[{start:g}, {end:g}]")


def meters_per_unit(stage: Usd.Stage) -> float:
    return float(UsdGeom.GetStageMetersPerUnit(stage))
