"""The paper's multi-channel binary tensor: one boolean channel per class, stored as a byte-deterministic
``.npz``.

``np.savez_compressed`` stamps each zip member with the current time, so two runs would differ; the file is
written here with ``zipfile`` and a fixed member date instead, and stays loadable by ``np.load``.
"""

from __future__ import annotations

import io
import zipfile
from pathlib import Path

import numpy as np

from synthua_usd.core.atomic import atomic_path
from synthua_usd.core.errors import InputError

#: The zip member holding the tensor: ``np.load(path)["onehot"]``.
MEMBER = "onehot"

#: Zip timestamp of every member (the earliest a zip can store), so that the bytes never depend on the clock.
_FIXED_DATE = (1980, 1, 1, 0, 0, 0)


def onehot(class_ids: np.ndarray, num_classes: int) -> np.ndarray:
    """(H, W) integer class ids -> (num_classes, H, W) bool, channel c true where the class is c."""
    if class_ids.ndim != 2:
        raise InputError(f"class-id map: shape {class_ids.shape}; expected (H, W)")
    top = int(class_ids.max()) if class_ids.size else 0
    if top >= num_classes or (class_ids.size and int(class_ids.min()) < 0):
        raise InputError(f"class-id map: class id {top} present; expected ids in 0..{num_classes - 1}")
    return np.arange(num_classes).reshape(-1, 1, 1) == class_ids[None, :, :]


def write_onehot_npz(path: str | Path, tensor: np.ndarray) -> Path:
    """Write a (C, H, W) bool tensor as ``.npz`` (member ``onehot``, deflated) atomically, byte for byte the
    same for the same tensor."""
    if tensor.dtype != np.bool_ or tensor.ndim != 3:
        raise InputError(f"one-hot tensor: {tensor.dtype} of shape {tensor.shape}; expected (C, H, W) bool")
    buffer = io.BytesIO()
    np.lib.format.write_array(buffer, np.ascontiguousarray(tensor), allow_pickle=False)
    info = zipfile.ZipInfo(f"{MEMBER}.npy", date_time=_FIXED_DATE)
    info.compress_type = zipfile.ZIP_DEFLATED
    info.create_system = 3  # Unix, whatever the platform, so the header bytes do not vary
    info.external_attr = 0o644 << 16
    path = Path(path)
    with atomic_path(path) as tmp:
        with zipfile.ZipFile(tmp, "w") as archive:
            archive.writestr(info, buffer.getvalue(), compress_type=zipfile.ZIP_DEFLATED, compresslevel=6)
    return path
