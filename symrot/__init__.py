"""symrot: verified formulas and Taylor-safe code for vectorial parameterizations of rotation.

Bauchau & Trainelli, "The Vectorial Parameterization of Rotation", Nonlinear Dynamics 32 (2003).

>>> import symrot
>>> symrot.derive("4*tan(phi/4)").nu
cos(phi/4)**2

The names below are imported on first use (PEP 562), so that the commands can fix the hash seed
(:mod:`symrot.entry`) before SymPy is loaded.
"""

from __future__ import annotations

from importlib import import_module
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from symrot.api import DerivationResult, derive
    from symrot.core.errors import SymrotError
    from symrot.core.parsing import PHI, parse_expression
    from symrot.core.registry import lookup
    from symrot.kernels_api import emit, kernels

__all__ = ["PHI", "DerivationResult", "SymrotError", "derive", "emit", "kernels", "lookup",
           "parse_expression"]
__version__ = "0.1.0"

_HOME = {"DerivationResult": "api", "derive": "api", "SymrotError": "core.errors", "PHI": "core.parsing",
         "parse_expression": "core.parsing", "lookup": "core.registry", "kernels": "kernels_api",
         "emit": "kernels_api"}


def __getattr__(name: str) -> Any:
    if name in _HOME:
        value = getattr(import_module(f".{_HOME[name]}", __name__), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
