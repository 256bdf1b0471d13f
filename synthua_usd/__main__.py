"""``python -m synthua_usd``: the ``synthua`` command."""

from synthua_usd.cli.main import run

run()
