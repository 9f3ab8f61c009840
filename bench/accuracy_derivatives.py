"""Accuracy of the derivatives of issue 19 in the generated NumPy modules (docs/accuracy.md).

For each named parameterization, ``rotation_derivative``, ``rotation_transpose_derivative``,
``tangent_derivative``, ``tangent_transpose_derivative`` and ``tangent_inverse_derivative`` of
generated/numpy/NAME.py are evaluated at p = p(φ) u for |φ| in the sweep of bench/accuracy.py
(0, log-spaced [1e-300, φ_max − 1e-6], uniform over the upper range, φ_max − 10⁻ᵏ) with random unit
axes u and random a, and ``angular_acceleration`` at random ṗ, p̈, in float64 and float32. The
reference is tests/reference.py (R from eq 1, H from ω = H ṗ, differentiated again at 150 digits),
evaluated at the rounded inputs. Error: max |D − D_ref| / (ε max |D_ref|), the worst over the sweep.
Target ≤ 8 ulp, or 8 κ ulp ("conditioned") where the radial condition number κ of the derivative
(how much the one rounding of x = |p|² moves it) exceeds 1, next to singular edges. For α = H p̈ + Ḣ ṗ
κ is the larger of its radial condition and the cancellation (|H p̈| + |Ḣ ṗ|)/|α| of its two terms
(tests/test_derivatives.py: acceleration_condition).

Run: ``python bench/accuracy_derivatives.py [--points N] [--names a,b]`` (prints a Markdown table).
"""

from __future__ import annotations

import argparse
import sys
import warnings
from pathlib import Path
from types import ModuleType

import mpmath
import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "bench"))

from accuracy import sweep  # noqa: E402

from tests.reference import GeneratingFunction, Reference  # noqa: E402
from tests.test_derivatives import _as_array as _array  # noqa: E402
from tests.test_derivatives import _ulp, acceleration_condition, radial_condition  # noqa: E402
from tests.test_derivatives import load as load_module  # noqa: E402

NAMED = {"rotation_vector": "phi", "linear": "sin(phi)", "euler_rodrigues": "2*sin(phi/2)",
         "cayley_gibbs_rodrigues": "2*tan(phi/2)", "wiener_milenkovic": "4*tan(phi/4)",
         "det_h_one": "cbrt(6*(phi - sin(phi)))", "sine_m4": "4*sin(phi/4)"}
FUNCTIONS = {"rotation_derivative": "R", "rotation_transpose_derivative": "R_T",
             "tangent_derivative": "H", "tangent_transpose_derivative": "H_T",
             "tangent_inverse_derivative": "H_inverse"}
DTYPES = {"float64": np.float64, "float32": np.float32}
TARGET_ULP = 8.0


def load(name: str) -> ModuleType:
    return load_module(ROOT / "generated" / "numpy" / f"{name}.py", f"bench_{name}")


def measure(name: str, points: int, seed: int = 19) -> dict[tuple[str, str], tuple[float, float, float]]:
    """{(function, precision): (ulp, at φ, κ)} at the worst ulp/κ; NaN inside the range counts as inf.
    κ (radial condition of the derivative, tests/test_derivatives.py) is measured only where ulp > 8."""
    module = load(name)
    function = GeneratingFunction(NAMED[name])
    reference = Reference(function)
    rng = np.random.default_rng(seed)
    phi_max = float(function.phi_max)
    p_max = float(function.p_max())
    worst: dict[tuple[str, str], tuple[float, float, float]] = {}
    for angle in sweep(min(phi_max, 4 * np.pi), points):
        axis = rng.normal(size=3)
        axis /= np.linalg.norm(axis)
        a, pdot, pddot = (rng.normal(size=3) for _ in range(3))
        with mpmath.workdps(40):
            size = float(function.value(mpmath.mpf(angle)))
        for label, dtype in DTYPES.items():
            p = (size * axis).astype(dtype)
            if float(np.linalg.norm(p.astype(np.float64))) >= p_max * (1 - 4 * float(np.finfo(dtype).eps)):
                continue  # rounded onto the edge of the range: NaN by design
            if angle > 0 and not np.any(p):
                continue  # underflows to p = 0 in this precision
            suffix = "64" if dtype is np.float64 else "32"
            wide = p.astype(np.float64)
            if float(wide @ wide) >= float(module._DERIVATIVE_X_LIMIT[suffix]):
                continue  # beyond the documented domain of unbounded p: NaN by design
            ins = [v.astype(dtype) for v in (a, pdot, pddot)]
            exact = [list(v.astype(np.float64)) for v in (p, *ins)]
            values = {}
            with warnings.catch_warnings():
                warnings.simplefilter("error")
                for f in FUNCTIONS:
                    values[f] = getattr(module, f)(p, ins[0])
                values["angular_acceleration"] = module.angular_acceleration(p, ins[1], ins[2])
            refs = {f: _array(reference.derivative(exact[0], exact[1], t)) for f, t in FUNCTIONS.items()}
            _, alpha = reference.along(exact[0], exact[2], exact[3])
            refs["angular_acceleration"] = np.array([float(v) for v in alpha])
            for f, value in values.items():
                ulp = _ulp(value, refs[f], dtype)
                kappa = 1.0
                if ulp > TARGET_ULP and f in FUNCTIONS:  # next to a singular edge: its radial κ
                    kappa = max(1.0, radial_condition(reference, np.array(exact[0]), np.array(exact[1]),
                                                      FUNCTIONS[f], refs[f]))
                elif ulp > TARGET_ULP:  # α: radial κ or the cancellation of H p̈ and Ḣ ṗ
                    kappa = max(1.0, acceleration_condition(reference, np.array(exact[0]), np.array(exact[2]),
                                                            np.array(exact[3]), refs[f]))
                key = (f, label)
                if ulp / kappa >= worst.get(key, (-1.0, 0.0, 1.0))[0] / worst.get(key, (0, 0, 1.0))[2]:
                    worst[key] = (ulp, float(angle), kappa)
    return worst


def table(results: dict[str, dict[tuple[str, str], tuple[float, float, float]]]) -> str:
    lines = ["| parameterization | function | float64 ulp (at φ; κ) | ulp/κ | float32 ulp (at φ; κ) | ulp/κ "
             "| verdict |",
             "|---|---|---|---|---|---|---|"]
    for name, worst in results.items():
        for f in (*FUNCTIONS, "angular_acceleration"):
            cells = [worst.get((f, label)) for label in DTYPES]
            text = []
            for c in cells:
                text += [f"{c[0]:.3g} ({c[1]:.3g}; κ {c[2]:.2g})", f"{c[0] / c[2]:.3g}"] if c else ["—", "—"]
            raw = all(c is None or c[0] <= TARGET_ULP for c in cells)
            scaled = all(c is None or c[0] / c[2] <= TARGET_ULP for c in cells)
            verdict = "meets" if raw else ("conditioned" if scaled else "misses")
            lines.append(f"| {name} | {f} | {' | '.join(text)} | {verdict} |")
    return "\n".join(lines) + "\n"


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--points", type=int, default=12)
    parser.add_argument("--names", default=",".join(NAMED))
    args = parser.parse_args(argv)
    results = {name: measure(name, args.points) for name in args.names.split(",")}
    print(table(results), end="")
    return 0 if all(v[0] / v[2] <= TARGET_ULP for worst in results.values() for v in worst.values()) else 1


if __name__ == "__main__":
    raise SystemExit(main())
