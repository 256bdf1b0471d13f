"""The ``synthua`` command line."""
