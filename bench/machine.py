"""The machine a benchmark ran on, for the sentence that introduces its table.

Ratios measured in one run are comparable; absolute times and even ratios move between CPUs
(docs/performance.md was measured on more than one 2-core machine). Every bench names the CPU
model, the core count and the architecture, from ``/proc/cpuinfo`` where Linux has it.
"""

from __future__ import annotations

import os
import platform
from pathlib import Path

CPUINFO = Path("/proc/cpuinfo")


def cpu_model() -> str:
    """The CPU's model name (``/proc/cpuinfo``), else what :mod:`platform` knows."""
    if CPUINFO.exists():
        for line in CPUINFO.read_text(encoding="utf-8", errors="replace").splitlines():
            key, _, value = line.partition(":")
            if key.strip() == "model name" and value.strip():
                return value.strip()
    return platform.processor() or platform.machine() or "unknown CPU"


def description() -> str:
    """e.g. "AMD EPYC, 2 cores, x86_64"."""
    return f"{cpu_model()}, {os.cpu_count()} cores, {platform.machine()}"
