"""``python -m symrot`` is the ``symrot`` command."""

from .cli import main

raise SystemExit(main())
