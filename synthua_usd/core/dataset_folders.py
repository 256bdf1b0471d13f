"""What marks a folder as a dataset of ``synthua generate``, and the guard that keeps every other command's
outputs out of one. The marker names are owned here, below every writer (:func:`synthua_usd.core.atomic.output_set`
asks :func:`check_outside_datasets`); :class:`synthua_usd.dataset.layout.Layout` names the same files from them.
"""

from __future__ import annotations

from pathlib import Path

from synthua_usd.core.errors import echo as escape
from synthua_usd.core.errors import OutputError

#: The folder of the per-image records, the manifest and the run's configuration: a dataset's markers.
RECORDS = "records"
MANIFEST = "manifest.json"
CONFIG = "generate.json"


def is_dataset_folder(folder: Path) -> bool:
    """Whether ``folder`` holds a dataset of ``synthua generate``: its ``records/`` folder beside its
    ``manifest.json`` or ``generate.json`` (either name alone is common among other tools' files)."""
    folder = Path(folder)
    return (folder / RECORDS).is_dir() and ((folder / MANIFEST).is_file() or (folder / CONFIG).is_file())


def check_outside_datasets(out_dir: Path) -> None:
    """Refuse an output folder that is a dataset folder (:func:`is_dataset_folder`) or lies inside one: a
    report or a render written there would be files its manifest does not list, and could replace files it
    does. Only ``synthua generate`` writes into a dataset."""
    target = Path(out_dir).resolve()
    for folder in (target, *target.parents):
        if is_dataset_folder(folder):
            where = "is the dataset folder" if folder == target else "lies inside the dataset folder"
            raise OutputError(f"{escape(out_dir)}: the output folder {where} {escape(folder)}; expected a folder "
                              f"outside every dataset (only `synthua generate` writes into one)")
