"""``python -m symrot`` is the ``symrot`` command."""

from symrot.entry import command

raise SystemExit(command())
