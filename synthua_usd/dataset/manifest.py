"""Provenance of a dataset: file checksums and the manifest document.

The manifest (``manifest.json``) is written last by ``synthua generate``. It records the software that
made the dataset (synthua, usd-core, mitsuba and the Mitsuba variant), the generation config, the hash of
the composed layer stack, and per image its seed, its name and every file with its SHA-256 and size; then
the dataset-level files (COCO, panoptic, tables...) the same way. It holds no times or dates: two runs
with the same config and seed on the same variant write the same manifest, byte for byte.
"""

from __future__ import annotations

import hashlib
from pathlib import Path
from typing import Any, NotRequired, TypedDict

from synthua_usd.core.errors import OutputError
from synthua_usd.dataset.layout import inside
from synthua_usd.dataset.record import REJECTED, FileEntry

#: Bytes read at a time when hashing files.
_CHUNK = 1 << 20


class ManifestImage(TypedDict):
    """One image of the manifest (``images[]``): its files with their checksums, and its record's QA verdict."""

    id: int
    name: str
    split: str
    files: list[FileEntry]
    seed: NotRequired[int]
    layer_stack: NotRequired[str]
    #: The verdict of the image's record (``qa.verdict``); an image without one counts as accepted.
    qa: NotRequired[str]


class Manifest(TypedDict):
    """``manifest.json`` (``schemas/manifest.schema.json``)."""

    provenance: dict[str, Any]
    images: list[ManifestImage]
    dataset_files: list[FileEntry]


def sha256_file(path: str | Path) -> str:
    digest = hashlib.sha256()
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(_CHUNK), b""):
            digest.update(block)
    return digest.hexdigest()


def file_entry(root: Path, relative: str) -> FileEntry:
    """``{"path", "sha256", "bytes"}`` of the file ``root / relative``."""
    path = Path(root) / relative
    return FileEntry(path=relative, sha256=sha256_file(path), bytes=path.stat().st_size)


def files_written(root: Path, checksums: dict[str, FileEntry]) -> bool:
    """Whether a record's ``checksums`` name files, each of which is in the dataset at ``root`` with its recorded size:
    what the resumption of generate and of the sequences takes as a finished image (an edited record naming a path
    outside the dataset: not finished; the checksums themselves are ``synthua verify``'s to compare)."""
    try:
        return bool(checksums) and all(inside(root, e["path"]).is_file()
                                       and inside(root, e["path"]).stat().st_size == e["bytes"]
                                       for e in checksums.values())
    except (OSError, OutputError):
        return False


def manifest_document(*, provenance: dict, images: list[dict], dataset_files: list[FileEntry]) -> dict:
    """The manifest: ``provenance`` (software versions, variant, config and its hash, layer stack digest),
    one entry per image (``id``, ``name``, ``split``, ``seed``, ``layer_stack``, ``files``: a list of file
    entries) and the dataset-level files."""
    return {"$schema": "manifest", "provenance": provenance, "images": images, "dataset_files": dataset_files}


def document_digest(document) -> str:
    """SHA-256 of a JSON-able value in canonical form (sorted keys, no spaces)."""
    from synthua_usd.core import json_text

    text = json_text.dumps(document, sort_keys=True, compact=True)
    return hashlib.sha256(text.encode("utf-8")).hexdigest()


def read_manifest(path: str | Path) -> Manifest:
    """The manifest at ``path``, read with the limits of every JSON input (:func:`synthua_usd.core.schemas.read_json`)
    and checked against ``schemas/manifest.schema.json``: anything else is an :class:`InputError` naming the
    file and the field (a missing file: "file not found")."""
    from synthua_usd.core.errors import InputError
    from synthua_usd.core.input_files import shown
    from synthua_usd.core.schemas import read_json, validate_document

    path = Path(path)
    if not path.exists():
        raise InputError(f"{shown(path)}: file not found; expected a complete dataset written by `synthua generate` "
                         f"(the manifest is written last)")
    document = read_json(path, "a dataset manifest")
    validate_document(document, "manifest", str(path))
    return document


def kept_images(manifest: Manifest, split: str | None = None) -> list[ManifestImage]:
    """The manifest's images that QA did not reject (:func:`synthua_usd.dataset.record.is_rejected`'s rule on the
    verdict the manifest copies from each record), of ``split`` when given, by image id: what every analysis and
    training set reads."""
    return sorted((e for e in manifest["images"] if e.get("qa") != REJECTED and (split is None or e["split"] == split)),
                  key=lambda e: e["id"])
