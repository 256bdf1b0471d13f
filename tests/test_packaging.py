"""The package list of pyproject.toml names every package of the source tree: a wheel built from it carries all of
synthua_usd (a package left off the list installs from an editable checkout but is missing from a wheel)."""

from __future__ import annotations

import tomllib

from conftest import REPO


def test_every_package_is_listed():
    listed = set(tomllib.loads((REPO / "pyproject.toml").read_text())["tool"]["setuptools"]["packages"])
    found = {".".join(p.parent.relative_to(REPO).parts) for p in (REPO / "synthua_usd").rglob("__init__.py")}
    found |= {"synthua_usd.assets.data", "synthua_usd.schema_files"}  # data folders shipped as packages
    assert listed == found, (sorted(found - listed), sorted(listed - found))
