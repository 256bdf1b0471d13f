"""Shared fixtures: paths, the class map, a CLI runner, and the shipped demo scenario."""

from __future__ import annotations

from pathlib import Path

import pytest

from synthua_usd.cli.main import main
from synthua_usd.taxonomy import ClassMap

REPO = Path(__file__).resolve().parents[1]
DATA = Path(__file__).resolve().parent / "data"
STAGES = REPO / "stages"
SCENARIO = STAGES / "scenario.usda"
SHARED = REPO.parent / "shared"


@pytest.fixture(scope="session")
def class_map() -> ClassMap:
    return ClassMap.default()


@pytest.fixture
def run_cli(capsys):
    """Run ``synthua ARGS...`` in-process; returns (exit status, stdout, stderr)."""
    def run(*args: str) -> tuple[int, str, str]:
        code = main([str(a) for a in args])
        out = capsys.readouterr()
        return code, out.out, out.err
    return run


@pytest.fixture(scope="session")
def demo_stage():
    from synthua_usd.usd.stage_io import open_stage

    return open_stage(SCENARIO)


THIRD_PARTY = SHARED / "data" / "third_party"


def third_party(*parts: str) -> Path:
    """A file of ../shared/data/third_party, or skip the test when the shared folder is not beside the clone."""
    path = THIRD_PARTY.joinpath(*parts)
    if not path.exists():
        pytest.skip(f"{path} is absent: third-party test data lives in ../shared beside the repository (CI has it)")
    return path
