"""The mutations of bench/mutations.py: faults a user would be hurt by, one per entry (issue 61).

The first six are the issue's: a validity test widened by 2 %, a constant of a committed module
37 ulp off, every series/closed-form switch moved up 4×, one Taylor coefficient scaled by 1.001,
compose's order swapped, a sign of the quaternion product flipped (the issue's target,
``symrot.core.operations.quaternion_product``, had no caller and is removed, so the same fault goes
into the product every C ``compose`` computes). The others cover the rest of the layers: the core's
definitions and derivatives, the validity analysis, the plan's polynomial degrees and Newton
counts, each printer, the C batch and in-place code, the NumPy and array runtimes, LaTeX, input
checks, the plan cache and atomic writes.

Each entry names the tests that should catch it; they are tests of ``make test``.
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Edit:
    """Replace ``old`` by ``new`` in every file matching ``path`` (a glob relative to the root).

    ``count``: occurrences expected in each file; 0 allows any number per file but at least one in
    all (for globs over modules that differ, e.g. inclusive and exclusive validity tests)."""

    path: str
    old: str
    new: str
    count: int = 1


@dataclass(frozen=True)
class Mutation:
    """One deliberate fault and the tests that should catch it."""

    name: str
    layer: str
    fault: str
    edits: tuple[Edit, ...]
    tests: tuple[str, ...]
    regenerate: tuple[tuple[str, str], ...] = ()
    """(producer prefix, parameterization) pairs for ``symrot.generate --only P --name N``."""
    parallel: bool = True
    """Run the tests under pytest-xdist (off for a few quick files)."""


NUMPY = "generated/numpy/*.py"
ARRAYS = "generated/[jt]*/*.py"
VALUES = "tests/test_independent_values.py"
EDGES = "tests/test_validity_edges.py"
FEW_ROWS_ENTRY = "                    q02 - b1, q12 + b0, a_k + c_k * s2)"

MUTATIONS: tuple[Mutation, ...] = (
    Mutation(
        "numpy-validity-widened", "runtime",
        "NumPy validity test `x <= 1.02 * P_MAX_SQUARED` (template and the modules of generated/numpy)",
        (Edit("symrot/backends/templates/numpy_module.py.j2", '}} P_MAX_SQUARED{%',
              '}} 1.02 * P_MAX_SQUARED{%'),
         Edit("symrot/backends/templates/numpy_module.py.j2", "    return x < _X_LIMIT[suffix]\n",
              "    return x < 1.02 * _X_LIMIT[suffix]\n"),
         Edit(NUMPY, "    return x <= P_MAX_SQUARED\n", "    return x <= 1.02 * P_MAX_SQUARED\n", 0),
         Edit(NUMPY, "    return x < P_MAX_SQUARED\n", "    return x < 1.02 * P_MAX_SQUARED\n", 0),
         Edit(NUMPY, "    return x < _X_LIMIT[suffix]\n", "    return x < 1.02 * _X_LIMIT[suffix]\n", 0)),
        (EDGES, "tests/test_numpy_domain_fuzz.py", "tests/test_domain.py")),
    Mutation(
        "numpy-constant-37ulp", "generated",
        "R_2 of generated/numpy/wiener_milenkovic.py: 0.5 → 0.500000000000002 (37 ulp in R)",
        (Edit("generated/numpy/wiener_milenkovic.py",
              "def _R_2_64(x, phi, s, d, sin_half, cos_half, span=None):\n    return numpy.asarray((0.5)",
              "def _R_2_64(x, phi, s, d, sin_half, cos_half, span=None):\n"
              "    return numpy.asarray((0.500000000000002)"),),
        (VALUES, "tests/test_numpy_backend.py")),
    Mutation(
        "plan-switches-4x", "plan",
        "every series/closed-form switch 4× higher, same polynomial (rotation_vector regenerated)",
        (Edit("symrot/plan/branches.py", "    return Branch(threshold, tuple(series[:degree]), closed, ",
              "    return Branch(4 * threshold, tuple(series[:degree]), closed, "),
         Edit("symrot/plan/branches.py", "best, edge,\n                  accurate_threshold, accurate_terms)",
              "best, edge,\n                  4 * accurate_threshold, accurate_terms)")),
        (VALUES, "tests/test_numpy_backend.py", "tests/test_generated.py"),
        (("numpy", "rotation_vector"),)),
    Mutation(
        "series-coefficient-1.001", "core",
        "the φ¹⁰ coefficient of every Taylor series scaled by 1.001 (rotation_vector regenerated)",
        (Edit("symrot/core/series.py",
              "    return [exact_number(domain.to_sympy(c)) if domain == EX else domain.to_sympy(c)\n"
              "            for c in series.coefficients(start, stop)]",
              "    return [(exact_number(domain.to_sympy(c)) if domain == EX else domain.to_sympy(c))\n"
              "            * (sp.Rational(1001, 1000) if k == 10 else 1)\n"
              "            for k, c in enumerate(series.coefficients(start, stop), start)]"),),
        ("tests/test_series.py", "tests/test_core.py", VALUES),
        (("numpy", "rotation_vector"),)),
    Mutation(
        "numpy-compose-swapped", "runtime",
        "NumPy compose computes R(p1) R(p2) instead of R(p2) R(p1) (cross product order; runtime "
        "and generated/numpy)",
        (Edit("symrot/backends/runtime/numpy_operations.py", "b0[..., None] * a + _cross(b, a)",
              "b0[..., None] * a + _cross(a, b)"),
         Edit(NUMPY, "b0[..., None] * a + _cross(b, a)", "b0[..., None] * a + _cross(a, b)")),
        ("tests/test_operations_numpy.py", VALUES, "tests/test_runtime.py")),
    Mutation(
        "c-quaternion-product-sign", "backend",
        "a sign of the quaternion product of C compose flipped (rotation_vector regenerated)",
        (Edit("symrot/backends/c_operations.py", '"a[0] * b[1] + b[0] * a[1] + (b[2] * a[3]',
              '"a[0] * b[1] + b[0] * a[1] - (b[2] * a[3]'),),
        ("tests/test_operations_c.py", VALUES),
        (("c", "rotation_vector"),)),
    Mutation(
        "core-epsilon-halved", "core",
        "ε = tan(φ/2)/p instead of 2 tan(φ/2)/p (eq 16), in every fresh derivation",
        (Edit("symrot/core/derivation.py", "    epsilon = 2 * sp.tan(PHI / 2) / p\n",
              "    epsilon = sp.tan(PHI / 2) / p\n"),),
        ("tests/test_core.py", "tests/test_validation.py", "tests/test_operations.py")),
    Mutation(
        "derivative-slope-series", "core",
        "the series of the slopes dc/dx shifted by one factor: j·d_(j+1) instead of (j+1)·d_(j+1) "
        "(rotation_vector regenerated)",
        (Edit("symrot/core/derivatives.py",
              "    return [(j + 1) * parent_series[j + 1] for j in range(n_terms)]",
              "    return [max(j, 1) * parent_series[j + 1] for j in range(n_terms)]"),),
        ("tests/test_derivatives.py", "tests/test_derivatives_core.py", VALUES),
        (("numpy", "rotation_vector"),)),
    Mutation(
        "validity-p-max-high", "core",
        "|p| at the edge of the validity range taken 1e-4 too large",
        (Edit("symrot/core/singularities.py", "        return abs(float(value))\n",
              "        return abs(float(value)) * 1.0001\n"),),
        ("tests/test_singularities.py", EDGES, "tests/test_domain.py"),
        (("numpy", "det_h_one"),)),
    Mutation(
        "plan-horner-short", "plan",
        "every Horner polynomial one term shorter than the plan chose (rotation_vector regenerated)",
        (Edit("symrot/plan/branches.py", "    return Branch(threshold, tuple(series[:degree]), closed,",
              "    return Branch(threshold, tuple(series[:max(1, degree - 1)]), closed,"),),
        (VALUES, "tests/test_numpy_backend.py"),
        (("numpy", "rotation_vector"),)),
    Mutation(
        "plan-newton-steps-dropped", "plan",
        "no Newton step after the angle's start (det_h_one regenerated; one step of the six already "
        "meets 4 ulp, the start alone is 1.6e4 ulp off)",
        (Edit("symrot/plan/angles.py", "float(np.finfo(dtype).eps)), count.steps)\n",
              "float(np.finfo(dtype).eps)), count.steps) * 0\n"),),
        (VALUES, "tests/test_newton_edge.py", "tests/test_numpy_backend.py"),
        (("numpy", "det_h_one"),)),
    Mutation(
        "c-validity-4ulp", "generated",
        "the double validity bound of generated/c/symrot_det_h_one.h 4 ulp wider",
        (Edit("generated/c/symrot_det_h_one.h", "x <= 11.243134665607636", "x <= 11.243134665607643", 0),),
        (EDGES, "tests/test_c_backend.py")),
    Mutation(
        "c-printer-reciprocal", "backend",
        "C printer: a/x**2 printed as a/x*x (the parentheses of a negative power dropped)",
        (Edit("symrot/backends/c_printer.py", '(sp.Float(1))}/{product}"',
              '(sp.Float(1))}/{product[1:-1]}"'),),
        ("tests/test_c_backend.py", "tests/test_c_printer.py", VALUES),
        (("c", "rotation_vector"), ("c", "det_h_one"), ("c", "wiener_milenkovic"))),
    Mutation(
        "c-batch-skips-last", "backend",
        "C batch kernels skip the last vector of every block (rotation_vector regenerated)",
        (Edit("symrot/backends/c_batch.py", '{"kind": "loop", "header": "k = m; k-- > 0;"',
              '{"kind": "loop", "header": "k = m - 1; k-- > 0;"'),),
        ("tests/test_c_batch.py",),
        (("c", "rotation_vector"),)),
    Mutation(
        "c-in-place-unsafe", "backend",
        "C functions write outputs while inputs are still to be read (the in-place pass off)",
        (Edit("symrot/backends/c_backend.py",
              "    stored = [stored_last(function) for function in functions]  # outputs may alias inputs",
              "    stored = list(functions)"),),
        ("tests/test_c_aliasing.py",), (("c", "rotation_vector"),)),
    Mutation(
        "numpy-apply-transposed", "runtime",
        "NumPy omega/pdot apply the transpose: (v×p) for (p×v) (runtime and generated/numpy)",
        (Edit("symrot/backends/runtime/numpy_runtime.py", "    p_cross_v = _cross(p, v)\n",
              "    p_cross_v = _cross(v, p)\n"),
         Edit(NUMPY, "    p_cross_v = _cross(p, v)\n", "    p_cross_v = _cross(v, p)\n")),
        (VALUES, "tests/test_numpy_backend.py")),
    Mutation(
        "numpy-few-rows-entry-sign", "runtime",
        "NumPy tensors of a few rows (the scalar path): entry (2, 0) as q02 + b1 for q02 - b1 "
        "(runtime and generated/numpy)",
        (Edit("symrot/backends/runtime/numpy_runtime.py", FEW_ROWS_ENTRY, FEW_ROWS_ENTRY.replace("-", "+")),
         Edit(NUMPY, FEW_ROWS_ENTRY, FEW_ROWS_ENTRY.replace("-", "+"))),
        ("tests/test_runtime.py", VALUES)),
    Mutation(
        "series-tables-first-term", "backend",
        "Python modules: a polynomial reads any coefficient tuple with the same constant term "
        "(rotation_vector regenerated)",
        (Edit("symrot/backends/series_tables.py", "if stored[:common] == values[:common]:",
              "if stored[:1] == values[:1]:"),),
        (VALUES, "tests/test_runtime.py"),
        (("numpy", "rotation_vector"),)),
    Mutation(
        "numpy-printer-constants-8-digits", "backend",
        "NumPy printer rounds rational constants to 8 digits (det_h_one regenerated)",
        (Edit("symrot/backends/numpy_backend.py", "        return repr(float(expr))\n",
              "        return repr(float(f\"{float(expr):.8g}\"))\n"),),
        (VALUES, "tests/test_numpy_backend.py"),
        (("numpy", "det_h_one"),)),
    Mutation(
        "array-compose-swapped", "runtime",
        "JAX/PyTorch compose computes R(p1) R(p2) (array runtime and generated/jax, generated/torch)",
        (Edit("symrot/backends/runtime/array_runtime.py", "b0[..., None] * a + _cross(b, a)",
              "b0[..., None] * a + _cross(a, b)"),
         Edit(ARRAYS, "b0[..., None] * a + _cross(b, a)", "b0[..., None] * a + _cross(a, b)")),
        ("tests/test_array_backends.py", VALUES, "tests/test_runtime.py")),
    Mutation(
        "latex-minus-dropped", "backend",
        "LaTeX: the minus sign of a slashed inner fraction dropped (tables and sheets regenerated)",
        (Edit("symrot/backends/latex.py", '            sign = "- "\n', '            sign = ""\n'),),
        ("tests/test_latex.py", "tests/test_latex_values.py"),
        (("latex", ""),)),
    Mutation(
        "cli-bad-input-exit-1", "cli",
        "bad input (a SymrotError) exits 1 instead of the documented usage status 2",
        (Edit("symrot/cli/__init__.py",
              "    except SymrotError as exc:\n        print(f\"symrot: error: {exc}\", file=sys.stderr)\n"
              "        return EXIT_USAGE\n",
              "    except SymrotError as exc:\n        print(f\"symrot: error: {exc}\", file=sys.stderr)\n"
              "        return 1\n"),),
        ("tests/test_cli_conventions.py", "tests/test_cli.py")),
    Mutation(
        "cache-checksum-skipped", "cli",
        "plan cache entries read without checking their header and checksum",
        (Edit("symrot/cli/plan_cache.py",
              "    if header != expected or canonical_json(header) != header_line:",
              "    if header[\"key\"] != key:"),),
        ("tests/test_plan_cache.py",)),
    Mutation(
        "c-batch-discarded-lanes-at-zero", "backend",
        "C batch kernels give discarded lanes 0, not the safe point (0/0 raises FE_INVALID)",
        (Edit("symrot/backends/c_batch.py",
              '"value": "x_safe" if name == "xc" else f"{name}_safe"} for name in closed]',
              '"value": "0"} for name in closed]'),),
        ("tests/test_c_batch_flags.py",), (("c", "rotation_vector"),)),
    Mutation(
        "kernels-checksum-skipped", "api",
        "symrot.kernels imports a kept module without checking its SHA-256",
        (Edit("symrot/kernels_api.py",
              'if hashlib.sha256(module.read_bytes()).hexdigest() == checksum.read_text(encoding="ascii")'
              '.strip():', "if True:"),),
        ("tests/test_kernels_api.py",)),
    Mutation(
        "atomic-no-rollback", "cli",
        "replace_all does not undo the renames done when a later one fails",
        (Edit("symrot/core/atomic.py", "        for target, backup in reversed(done):",
              "        for target, backup in reversed(done[:0]):"),),
        ("tests/test_output_safety.py",)),
)
