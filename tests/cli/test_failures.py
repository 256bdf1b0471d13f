"""The one place failures become messages: Python warnings are held back while a command runs."""

import logging

import pytest

from synthua_usd.cli.failures import python_warnings_held

#: Where ``logging.captureWarnings`` (on for every command) sends Python's warnings.
WARNINGS = logging.getLogger("py.warnings")


@pytest.fixture
def shown():
    """The records the ``py.warnings`` logger hands to its handlers."""
    records: list[logging.LogRecord] = []
    handler = logging.Handler()
    handler.emit = records.append
    WARNINGS.addHandler(handler)
    try:
        yield records
    finally:
        WARNINGS.removeHandler(handler)


def test_warnings_are_shown_after_a_command_that_succeeds(shown):
    with python_warnings_held(keep_on_failure=False):
        WARNINGS.warning("x.py:1: RuntimeWarning: overflow encountered in multiply")
        assert shown == []
    assert len(shown) == 1 and "overflow encountered" in shown[0].getMessage()


def test_warnings_before_a_failure_are_dropped_unless_kept(shown):
    for keep in (False, True):
        with pytest.raises(ValueError):
            with python_warnings_held(keep_on_failure=keep):
                WARNINGS.warning(f"x.py:1: RuntimeWarning: invalid value encountered in det ({keep})")
                raise ValueError("the one error line")
    assert [("(True)" in r.getMessage()) for r in shown] == [True]
