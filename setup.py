"""The package list, found when the wheel is built (everything else is in pyproject.toml): every folder under
synthua_usd/ (packages and the body bank's data folder), so that a new one cannot be left out, and the top-level
schemas/ folder, shipped inside the package as synthua_usd.schema_files ([tool.setuptools.package-dir])."""

from setuptools import find_namespace_packages, setup

found = find_namespace_packages(include=["synthua_usd", "synthua_usd.*"], exclude=["*.__pycache__"])
setup(packages=[*found, "synthua_usd.schema_files"])
