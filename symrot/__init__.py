"""symrot: verified formulas and Taylor-safe code for vectorial parameterizations of rotation.

Bauchau & Trainelli, "The Vectorial Parameterization of Rotation", Nonlinear Dynamics 32 (2003).

>>> import symrot
>>> symrot.derive("4*tan(phi/4)").nu
cos(phi/4)**2
"""

from .api import DerivationResult, derive
from .errors import SymrotError
from .parsing import PHI, parse_expression
from .registry import lookup

__all__ = ["PHI", "DerivationResult", "SymrotError", "derive", "lookup", "parse_expression"]
__version__ = "0.1.0"
