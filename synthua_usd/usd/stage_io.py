"""Opening stages safely: missing and malformed files become one-line :class:`StageError` messages."""

from __future__ import annotations

import math
import os
import re
from pathlib import Path

from pxr import Sdf, Tf, Usd, UsdGeom

from synthua_usd.composition.scenario import StageMetadata
from synthua_usd.core.errors import StageError, echo

USD_SUFFIXES = (".usda", ".usdc", ".usd", ".usdz")


def tf_message(exc: Exception) -> str:
    """The message of a Tf error (``Error in '...' at line N in file ... : 'message'``) on one line."""
    text = _first_line(exc)
    m = re.search(r" : '(.*)'$", text)
    return m.group(1) if m else text


def _first_line(exc: Exception) -> str:
    try:
        text = str(exc).strip()
    except UnicodeDecodeError:  # OpenUSD quotes the offending bytes, which Python cannot decode
        return "it holds bytes that are not UTF-8; expected UTF-8 text or a binary crate file"
    # Tf errors carry "Error in '...' at line N in file ... : 'message'"; keep the message.
    for line in text.splitlines():
        if line.strip():
            text = line.strip()
            break
    return text


def _read(path: Path, what: str, opener):
    """``opener()`` after the file checks; USD's parse errors become one :class:`StageError` naming ``path``."""
    _check_file(path)
    try:
        result = opener()
    except Tf.ErrorException as exc:
        raise StageError(f"{path}: not a readable USD {what}: {echo(_first_line(exc))}") from None
    except UnicodeDecodeError as exc:
        raise StageError(f"{path}: not a readable USD {what}: byte 0x{exc.object[exc.start]:02x} is not UTF-8; "
                         f"expected UTF-8 text or a binary crate file") from None
    if result is None:
        raise StageError(f"{path}: not a readable USD {what}")
    return result


def open_layer(path: str | Path) -> Sdf.Layer:
    """Open one layer file (no composition)."""
    path = Path(path)
    return _read(path, "layer", lambda: Sdf.Layer.FindOrOpen(str(path)))


def open_stage(path: str | Path, allow_external_assets: bool = False, layers=()) -> Usd.Stage:
    """Open and compose a stage with all payloads loaded; ``layers`` (layer files, strongest first) are composed
    over it through its session layer, never written into its files (a randomisation layer of
    ``synthua randomise``, an override of one's own).

    Raises :class:`StageError` naming the file when it is missing, not USD, or fails to parse; when any
    sublayer, reference or payload is missing, unreadable or cyclic (OpenUSD only warns and skips it, which
    would silently render a scene without it); and, unless ``allow_external_assets``, when a layer it
    composes, or a texture file a UsdUVTexture reads, lies outside the folder tree of the root layer (or of
    one of ``layers``).
    """
    path = Path(path)
    stage = _read(path, "stage", lambda: Usd.Stage.Open(str(path), Usd.Stage.LoadAll))
    extra = [Path(layer) for layer in layers]
    for layer in extra:
        open_layer(layer)  # the file checks, one line naming it
    if extra:
        session = stage.GetSessionLayer()
        for k, layer in enumerate(extra):
            session.subLayerPaths.insert(k, str(layer.resolve()))
    errors = stage.GetCompositionErrors()
    if errors:
        more = f" (and {len(errors) - 1} more)" if len(errors) > 1 else ""
        first = str(errors[0]).strip().removesuffix("skipping.").strip().rstrip(";. ")
        raise StageError(f"{path}: {echo(first, 400)}{more}; expected every sublayer, reference and payload of the "
                         f"stage to exist, open and compose without cycles")
    if not allow_external_assets:
        check_layers_inside(stage, path, extra)
        check_textures_inside(stage, path, extra)
    check_stage_metadata(stage, path)
    return stage


def check_layers_inside(stage: Usd.Stage, path: Path, extra=()) -> None:
    """Refuse layers outside the root layer's folder tree (a scenario that reads ``/etc`` or ``../..``) and the
    folder trees of the ``extra`` layer files composed over it."""
    root = path.resolve().parent
    roots = [root, *(Path(p).resolve().parent for p in extra)]
    for layer in stage.GetUsedLayers():
        if layer.anonymous or not layer.realPath:
            continue
        real = Path(layer.realPath).resolve()
        if not any(real.is_relative_to(r) for r in roots):
            raise StageError(f"{path}: composes {echo(real)}, outside the scenario's folder {echo(root)}; expected "
                             f"layers in that folder tree (pass --allow-external-assets to accept it)")


def check_textures_inside(stage: Usd.Stage, path: Path, extra=()) -> None:
    """Refuse texture files (``UsdUVTexture`` ``inputs:file``) outside the root layer's folder tree (and those of
    the ``extra`` layer files), as layers are refused: a texture is read like a layer is. Missing files are left
    to the reader (a warning and the constant) and to validation (an error)."""
    root = path.resolve().parent
    roots = [root, *(Path(p).resolve().parent for p in extra)]
    prims = list(stage.Traverse()) + [p for proto in stage.GetPrototypes() for p in Usd.PrimRange(proto)]
    for prim in prims:
        if prim.GetTypeName() != "Shader" or prim.GetAttribute("info:id").Get() != "UsdUVTexture":
            continue
        asset = prim.GetAttribute("inputs:file").Get()
        resolved = asset.resolvedPath if isinstance(asset, Sdf.AssetPath) else ""
        if resolved and not any(Path(resolved).resolve().is_relative_to(r) for r in roots):
            raise StageError(f"{path}: {prim.GetPath()} reads the texture {echo(Path(resolved).resolve())}, outside the "
                             f"scenario's folder {echo(root)}; expected textures in that folder tree (pass "
                             f"--allow-external-assets to accept it)")


def check_stage_metadata(stage: Usd.Stage, path: Path) -> None:
    """metersPerUnit finite and > 0, upAxis Y or Z, timeCodesPerSecond finite and > 0, a finite time range with
    start <= end: every length, direction and time code depends on them."""
    mpu = UsdGeom.GetStageMetersPerUnit(stage)
    if not (math.isfinite(mpu) and mpu > 0):
        raise StageError(f"{path}: metersPerUnit is {mpu!r}; expected a finite number > 0 (1 for metres)")
    up = UsdGeom.GetStageUpAxis(stage)
    if up not in (UsdGeom.Tokens.y, UsdGeom.Tokens.z):
        raise StageError(f"{path}: upAxis is {echo(up)!r}; expected 'Y' or 'Z'")
    fps = stage.GetTimeCodesPerSecond()
    if not (math.isfinite(fps) and fps > 0):
        raise StageError(f"{path}: timeCodesPerSecond is {fps!r}; expected a finite number > 0")
    start, end = stage.GetStartTimeCode(), stage.GetEndTimeCode()
    if not (math.isfinite(start) and math.isfinite(end)):
        raise StageError(f"{path}: the time range is [{start!r}, {end!r}] (startTimeCode, endTimeCode); expected "
                         f"finite time codes")
    if stage.HasAuthoredTimeCodeRange() and start > end:
        raise StageError(f"{path}: startTimeCode {start:g} is after endTimeCode {end:g}; expected start <= end")


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


_CONTROL_OR_SPACE = re.compile(r"[\x00-\x20\x7f]")


def prim_path(text: str, where: str, what: str) -> Sdf.Path:
    """``text`` as an absolute prim path, exactly as written: refused (a :class:`StageError` naming ``where`` and
    ``what``, e.g. ``--camera``) when it holds control characters or spaces, is not an absolute prim path
    (a relative path, a property or a variant selection), or is not the path SdfPath reads from it (SdfPath
    stops reading at a newline: ``/World/Cam\\nX`` would name ``/World/Cam``)."""
    refused = StageError(f"{where}: {what} '{echo(text)}' is not a prim path; expected an absolute prim path such "
                         f"as /World/Cameras/CCTV")
    if _CONTROL_OR_SPACE.search(text) or not text.startswith("/") or not Sdf.Path.IsValidPathString(text):
        raise refused
    path = Sdf.Path(text)
    if not (path.IsPrimPath() and path.IsAbsolutePath()) or path.ContainsPrimVariantSelection() \
            or str(path) != text:
        raise refused
    return path


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


def stage_metadata(stage: Usd.Stage) -> StageMetadata:
    """What ``stage`` states of its axis, units and time: its upAxis, metersPerUnit, timeCodesPerSecond, time range
    (:func:`time_range`; a stage without one: its start time code for both ends) and default prim (its root
    layer's, else ``World``). A layer authored over the stage states the same (a caller whose layer differs, e.g.
    one rooted at ``/World`` whatever the stage's default prim, replaces that field). Raises :class:`InputError`
    for metadata :func:`check_stage_metadata` refuses (:func:`open_stage` has checked them)."""
    span = time_range(stage)
    start, end = span if span else (stage.GetStartTimeCode(),) * 2
    return StageMetadata(up_axis=str(UsdGeom.GetStageUpAxis(stage)),
                         meters_per_unit=float(UsdGeom.GetStageMetersPerUnit(stage)),
                         time_codes_per_second=float(stage.GetTimeCodesPerSecond()), start_time_code=float(start),
                         end_time_code=float(end), default_prim=stage.GetRootLayer().defaultPrim or "World")


def layer_stack_digest(stage: Usd.Stage) -> dict:
    """The composed stage's provenance: SHA-256 of each layer file it uses (sublayers, references, payloads;
    anonymous layers such as the session layer left out), by path relative to the root layer's folder, and
    one SHA-256 over them all (``digest``): two stages with the same digest compose the same bytes."""
    import hashlib

    root = Path(stage.GetRootLayer().realPath).resolve().parent
    layers = {}
    for layer in stage.GetUsedLayers():
        if layer.anonymous or not layer.realPath:
            continue
        real = Path(layer.realPath).resolve()
        name = os.path.relpath(real, root).replace(os.sep, "/")
        layers[name] = hashlib.sha256(real.read_bytes()).hexdigest()
    total = hashlib.sha256("".join(f"{k}\0{v}\n" for k, v in sorted(layers.items())).encode("utf-8")).hexdigest()
    return {"digest": total, "layers": dict(sorted(layers.items()))}
