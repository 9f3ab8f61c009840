"""``python -m symrot`` is the ``symrot`` command."""

from .entry import command

raise SystemExit(command())
