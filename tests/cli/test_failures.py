"""The one place failures become messages: Python warnings are held back while a command runs."""

import logging
import warnings

import pytest

from synthua_usd.cli.failures import python_warnings_held


@pytest.fixture
def shown():
    """The records the ``py.warnings`` logger hands to its handlers."""
    records: list[logging.LogRecord] = []
    handler = logging.Handler()
    handler.emit = records.append
    logger = logging.getLogger("py.warnings")
    logger.addHandler(handler)
    logging.captureWarnings(True)
    try:
        yield records
    finally:
        logging.captureWarnings(False)
        logger.removeHandler(handler)


def test_warnings_are_shown_after_a_command_that_succeeds(shown):
    with python_warnings_held(keep_on_failure=False):
        warnings.warn("overflow encountered in multiply", RuntimeWarning, stacklevel=1)
        assert shown == []
    assert len(shown) == 1 and "overflow encountered" in shown[0].getMessage()


def test_warnings_before_a_failure_are_dropped_unless_kept(shown):
    for keep in (False, True):
        with pytest.raises(ValueError):
            with python_warnings_held(keep_on_failure=keep):
                warnings.warn(f"invalid value encountered in det ({keep})", RuntimeWarning, stacklevel=1)
                raise ValueError("the one error line")
    assert [("(True)" in r.getMessage()) for r in shown] == [True]
