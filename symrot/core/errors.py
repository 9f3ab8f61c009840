"""Errors raised by symrot. Every user-facing failure is a :class:`SymrotError`.

The command line turns any :class:`SymrotError` into a one-line message and exit status 2.
"""


class SymrotError(Exception):
    """Base class of all errors symrot reports to users."""


class ParseError(SymrotError):
    """A user expression was rejected by the safe parser."""


class InvalidGeneratingFunction(SymrotError):
    """p(phi) violates a requirement of Section 3.1 (odd, p(0) = 0, finite non-zero kappa, analytic)."""


class NonAnalyticError(InvalidGeneratingFunction):
    """The expression has no Taylor (or Laurent) series at phi = 0."""


class SymrotTimeout(SymrotError):
    """A bounded symbolic step ran out of time."""


class UnknownName(SymrotError):
    """A registry identifier that does not exist."""


class NonFiniteLiteral(SymrotError):
    """A constant of a plan is not finite in the target precision (it would print as ``inf``)."""
