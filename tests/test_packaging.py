"""The package layout: the package root holds only ``__init__``, ``__main__`` and the layer packages, and the wheel's
package list (setup.py, found when it is built) is every folder of synthua_usd plus the schemas: a new package cannot
be left out of a wheel (one missing from a hand-kept list installs from an editable checkout but not from a wheel)."""

from __future__ import annotations

import runpy
from unittest import mock

from conftest import REPO


def test_the_package_list_is_every_folder_of_the_package_and_the_schemas():
    with mock.patch("setuptools.setup") as setup:
        runpy.run_path(str(REPO / "setup.py"))
    listed = set(setup.call_args.kwargs["packages"])
    found = {".".join(p.relative_to(REPO).parts) for p in (REPO / "synthua_usd").rglob("*")
             if p.is_dir() and p.name != "__pycache__"} | {"synthua_usd"}
    assert listed == found | {"synthua_usd.schema_files"}, (sorted(found - listed), sorted(listed - found))


def test_the_package_root_holds_only_its_entry_points_and_the_layer_packages():
    modules = sorted(p.name for p in (REPO / "synthua_usd").glob("*.py"))
    assert modules == ["__init__.py", "__main__.py"], modules
    for folder in (REPO / "synthua_usd").iterdir():
        if folder.is_dir() and folder.name != "__pycache__":
            assert (folder / "__init__.py").is_file(), folder
