"""JAX backend (``--emit jax``): the plan as a branch-free, jit-able JAX module.

A thin adapter of :mod:`symrot.backends.array_backend`, which prints the plan for both JAX and
PyTorch; this module only names the framework.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from symrot.backends.array_backend import emit_framework
from symrot.backends.array_backend import module_source as array_module_source
from symrot.plan.ir import EvaluationPlan


def module_source(plan: EvaluationPlan) -> str:
    return array_module_source(plan, "jax")


def emit(derivation: Any, name: str, out: Path) -> list[Path]:
    """Write ``out/NAME.py`` (a JAX module) for ``derivation``; return the written paths."""
    return emit_framework(derivation, name, out, "jax")
