"""PyTorch backend (``--emit torch``): the plan as a branch-free PyTorch module (torch.func-ready).

A thin adapter of :mod:`symrot.backends.array_backend`, which prints the plan for both PyTorch and
JAX; this module only names the framework.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from symrot.backends.array_backend import emit_framework
from symrot.backends.array_backend import module_source as array_module_source
from symrot.plan.ir import EvaluationPlan


def module_source(plan: EvaluationPlan) -> str:
    return array_module_source(plan, "torch")


def emit(derivation: Any, name: str, out: Path) -> list[Path]:
    """Write ``out/NAME.py`` (a PyTorch module) for ``derivation``; return the written paths."""
    return emit_framework(derivation, name, out, "torch")
