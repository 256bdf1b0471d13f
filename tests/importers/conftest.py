"""Fixtures of the hostile-input suite (defined in importers/hostile_corpus.py, shared by tests/importers and
tests/cli): an earlier import, a working folder holding a copy of it, and the in-process refusal check."""

from importers.hostile_corpus import earlier_import, refuse, workdir  # noqa: F401 (fixtures)
