"""``symrot solve PROPERTY``: the generating function that has a required property (Section 3.2)."""

from __future__ import annotations

import argparse
from typing import Any

from symrot.cli import strict_json
from symrot.core.budget import stage
from symrot.core.registry import find_by_expression
from symrot.core.solve import solve_property


def register(subparsers: Any) -> None:
    parser = subparsers.add_parser(
        "solve", help="derive p(phi) from a required property, e.g. 'det_H = const'",
        description="Solve for the generating function with a property written as a relation "
        "between p, p_prime, nu, eps, mu, det_H and phi (unknown constant: c or const), e.g. "
        "'mu = nu**2/eps' (eq 33), 'det_H = const' (eq 35), 'nu**2 = c*eps' (eq 31). "
        "Constants are fixed by p(0) = 0 and p/phi -> 1 (eq 13).",
    )
    parser.add_argument("property", help="'LHS = RHS'")
    parser.add_argument("--m", type=int, default=None, metavar="M",
                        help="value of the name m (family order, eq 37), e.g. "
                        "--m 3 'mu = 1/sqrt(1 - p**2/m**2)'")
    parser.add_argument("--json", action="store_true", help="print one JSON object")
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    with stage("solving"):
        solution = solve_property(args.property, args.m)
    with stage("registry lookup"):
        entry = find_by_expression(solution.expression) if solution.expression is not None else None
    data = {
        "property": solution.property,
        "expression": None if solution.expression is None else str(solution.expression),
        "constant": None if solution.constant is None else str(solution.constant),
        "method": solution.method,
        "taylor": [str(c) for c in solution.taylor],
        "name": entry.identifier if entry else None,
        "equation": entry.equation if entry else None,
    }
    if args.json:
        print(strict_json.dumps(data, indent=2))
        return 0
    if solution.expression is None:
        print("No closed form found; exact Taylor series of p from a power-series ansatz:")
        print("  p(phi) = " + " + ".join(f"({c}) phi^{k}" for k, c in enumerate(solution.taylor) if c != 0)
              + f" + O(phi^{len(solution.taylor)})")
    else:
        named = f"    [{entry.identifier}, eq {entry.equation}]" if entry else ""
        print(f"p(phi) = {solution.expression}{named}")
        print("verified: the property holds at 50 digits; p is odd, analytic and kappa = 1")
    if solution.constant is not None:
        print(f"c = {solution.constant}")
    print(f"method: {solution.method}")
    return 0
