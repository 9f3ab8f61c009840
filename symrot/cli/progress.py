"""Progress on stderr for steps that can take more than a couple of seconds (audit, emit, plot,
``make generate``), drawn by tqdm.

Quiet when stderr is not a terminal (CI logs, pipes) or with ``--quiet``: stdout stays exactly
what the command prints, so scripts that read it are unaffected either way.
"""

from __future__ import annotations

import shutil
import sys
from collections.abc import Iterable, Iterator
from contextlib import contextmanager
from typing import TypeVar

from tqdm import tqdm

T = TypeVar("T")

_quiet = False


def set_quiet(quiet: bool) -> None:
    """``--quiet``: no progress output for the rest of the process."""
    global _quiet
    _quiet = quiet


def enabled() -> bool:
    return not _quiet and sys.stderr.isatty()


def _width() -> int:
    """The terminal's width; 80 columns where it reports none (a fresh pseudo-terminal)."""
    return shutil.get_terminal_size((80, 24)).columns


def each(items: Iterable[T], description: str, total: int | None = None) -> Iterator[T]:
    """Iterate over ``items`` with a progress bar labelled ``description``."""
    yield from tqdm(items, desc=description, total=total, disable=not enabled(), leave=False,
                    file=sys.stderr, unit="step", ncols=_width())


class Stages:
    """A bar over named stages: ``stages.start("planning")`` moves to the next one."""

    def __init__(self, bar: tqdm) -> None:
        self._bar = bar
        self._started = False

    def start(self, name: str) -> None:
        if self._started:
            self._bar.update(1)
        self._started = True
        self._bar.set_postfix_str(name, refresh=True)


@contextmanager
def stages(description: str, total: int) -> Iterator[Stages]:
    """A progress bar for a fixed sequence of ``total`` named stages."""
    with tqdm(total=total, desc=description, disable=not enabled(), leave=False, file=sys.stderr,
              bar_format="{desc}: {n_fmt}/{total_fmt} {postfix} [{elapsed}]", ncols=_width()) as bar:
        yield Stages(bar)
