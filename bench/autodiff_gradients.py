"""Gradients of R and of the tangent operator near the identity: symrot's JAX and PyTorch modules
beside the installable peers, against 60-digit mpmath (issue 20); and jit-compiled throughput of
``rotation_matrix`` for 10⁶ rotations beside the NumPy module and SciPy.

Accuracy: p = θ u (rotation vector, u a fixed random unit axis) at θ ∈ {0, 1e-8, 1e-4, 1e-2, 1,
π − 1e-6}, float64.  ∂R/∂p (3×3×3) by each framework's reverse mode (jax.jacrev,
torch.func.jacrev); ∂H/∂p likewise for the peers' left Jacobian I + (1 − cos θ)/θ² (p×) +
(θ − sin θ)/θ³ (p×)² (= symrot's H of the rotation vector, ω = H ṗ in the fixed frame).
Reference: tests/autodiff_reference.py (eq 1 differentiated analytically; H from its definition,
∂H/∂p by a 150-digit central difference).  Error: max |J − J_ref| / (ε · max |J_ref|) in ulp;
"NaN" where the framework returns a non-finite value.  Peers: jaxlie ``SO3.exp``, roma
``rotvec_to_rotmat``, kornia ``axis_angle_to_rotation_matrix`` and ``So3.exp`` / ``So3.left_jacobian``
(pytorch3d has no wheel for this platform and Python: not installable here).

Throughput: CPU time (time.process_time, best of 3 after a warm-up call that compiles) of
``rotation_matrix`` on 10⁶ random rotation vectors |p| < π, float64.  The machine is shared with
other jobs: compare the columns of one run, not runs.

Run: ``python bench/autodiff_gradients.py [--speed-only | --accuracy-only]`` (prints Markdown tables).
"""

from __future__ import annotations

import argparse
import importlib.util
import math
import sys
import time
from collections.abc import Callable
from pathlib import Path
from types import ModuleType
from typing import Any

import mpmath
import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from tests.autodiff_reference import AutodiffReference  # noqa: E402
from tests.reference import GeneratingFunction  # noqa: E402

THETAS = ("0", "1e-8", "1e-4", "1e-2", "1", "pi - 1e-6")
AXIS = np.array([0.48, -0.6, 0.64])
SIZE = 1_000_000


def load(kind: str, name: str = "rotation_vector") -> ModuleType:
    path = ROOT / "generated" / kind / f"{name}.py"
    spec = importlib.util.spec_from_file_location(f"bench_{kind}_{name}", path)
    assert spec and spec.loader
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def candidates() -> dict[str, tuple[Callable[[np.ndarray], np.ndarray] | None,
                                    Callable[[np.ndarray], np.ndarray] | None]]:
    """name → (∂R/∂p, ∂H/∂p) as functions of a float64 p (3,), or None when not offered."""
    out: dict[str, Any] = {}
    try:
        import jax
        jax.config.update("jax_enable_x64", True)
        import jax.numpy as jnp
        module = load("jax")

        def jax_jac(f: Callable[[Any], Any]) -> Callable[[np.ndarray], np.ndarray]:
            compiled = jax.jit(jax.jacrev(f))
            return lambda p: np.asarray(compiled(jnp.asarray(p)))

        out["symrot-jax"] = (jax_jac(module.rotation_matrix), jax_jac(module.tangent))
        try:
            import jaxlie
            out["jaxlie SO3.exp"] = (jax_jac(lambda p: jaxlie.SO3.exp(p).as_matrix()), None)
        except ImportError:
            pass
    except ImportError:
        pass
    try:
        import torch
        module = load("torch")

        def torch_jac(f: Callable[[Any], Any]) -> Callable[[np.ndarray], np.ndarray]:
            jacobian = torch.func.jacrev(f)
            return lambda p: jacobian(torch.as_tensor(p)).detach().numpy()

        out["symrot-torch"] = (torch_jac(module.rotation_matrix), torch_jac(module.tangent))
        try:
            import roma
            out["roma rotvec_to_rotmat"] = (torch_jac(roma.rotvec_to_rotmat), None)
        except ImportError:
            pass
        try:
            import kornia.geometry.conversions as conversions
            from kornia.geometry.liegroup import So3
            out["kornia axis_angle_to_rotation_matrix"] = (
                torch_jac(lambda p: conversions.axis_angle_to_rotation_matrix(p[None])[0]), None)
            out["kornia So3.exp / left_jacobian"] = (
                torch_jac(lambda p: So3.exp(p).matrix()), torch_jac(So3.left_jacobian))
        except ImportError:
            pass
    except ImportError:
        pass
    return out


def ulp(value: np.ndarray, reference: np.ndarray) -> float:
    if not np.isfinite(value).all():
        return math.nan
    scale = float(np.max(np.abs(reference)))
    return float(np.max(np.abs(value - reference))) / (scale * np.finfo(float).eps)


def accuracy() -> tuple[list[str], dict[str, list[tuple[float, float]]]]:
    reference = AutodiffReference(GeneratingFunction("phi", phi_max_text="2*pi"))
    points = []
    for text in THETAS:
        with mpmath.workdps(80):
            theta = mpmath.pi - mpmath.mpf("1e-6") if text == "pi - 1e-6" else mpmath.mpf(text)
        p = reference.point(theta, AXIS, np.float64)
        points.append((p, reference.rotation_jacobian(p), reference.tangent_jacobian(p)))
    rows: dict[str, list[tuple[float, float]]] = {}
    for name, (rotation, tangent) in candidates().items():
        rows[name] = [(ulp(rotation(p), dr) if rotation else math.nan,
                       ulp(tangent(p), dh) if tangent else math.nan) for p, dr, dh in points]
        # a tangent operator in the other convention (body frame, H^T) would show up as a large error
    return list(THETAS), rows


def _best_cpu_time(call: Callable[[], Any], repeats: int = 3) -> float:
    call()  # warm-up: compiles under jit
    best = math.inf
    for _ in range(repeats):
        start = time.process_time()
        call()
        best = min(best, time.process_time() - start)
    return best


def throughput() -> dict[str, float]:
    rng = np.random.default_rng(0)
    axes = rng.normal(size=(SIZE, 3))
    p = axes / np.linalg.norm(axes, axis=1, keepdims=True) * rng.uniform(0, 3.1, (SIZE, 1))
    out = {"symrot NumPy module": _best_cpu_time(lambda: load("numpy").rotation_matrix(p))}
    from scipy.spatial.transform import Rotation
    out["scipy Rotation.from_rotvec().as_matrix()"] = _best_cpu_time(
        lambda: Rotation.from_rotvec(p).as_matrix())
    try:
        import jax
        jax.config.update("jax_enable_x64", True)
        module = load("jax")
        compiled = jax.jit(module.rotation_matrix)
        data = jax.numpy.asarray(p)
        out["symrot-jax (jax.jit)"] = _best_cpu_time(lambda: compiled(data).block_until_ready())
    except ImportError:
        pass
    try:
        import torch
        module = load("torch")
        tensor = torch.as_tensor(p)
        out["symrot-torch (eager)"] = _best_cpu_time(lambda: module.rotation_matrix(tensor))
    except ImportError:
        pass
    return out


def _cell(value: float) -> str:
    if math.isnan(value):
        return "NaN"
    return f"{value:.1f}" if value < 1e4 else f"{value:.1e}"


def report(thetas: list[str], rows: dict[str, list[tuple[float, float]]]) -> str:
    lines = ["| library | " + " | ".join(f"θ = {t}" for t in thetas) + " |",
             "|---|" + "---|" * len(thetas)]
    for name, cells in rows.items():
        lines.append(f"| {name}: ∂R/∂p | " + " | ".join(_cell(r) for r, _ in cells) + " |")
    for name, cells in rows.items():
        if not all(math.isnan(h) for _, h in cells):
            lines.append(f"| {name}: ∂H/∂p | " + " | ".join(_cell(h) for _, h in cells) + " |")
    return "\n".join(lines) + "\n"


def speed_report(times: dict[str, float]) -> str:
    lines = ["| implementation | CPU seconds for 10⁶ rotations | million rotations per CPU second |",
             "|---|---|---|"]
    for name, seconds in times.items():
        lines.append(f"| {name} | {seconds:.3f} | {SIZE / seconds / 1e6:.1f} |")
    return "\n".join(lines) + "\n"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--speed-only", action="store_true")
    parser.add_argument("--accuracy-only", action="store_true")
    args = parser.parse_args()
    if not args.speed_only:
        print(report(*accuracy()))
    if not args.accuracy_only:
        print(speed_report(throughput()))


if __name__ == "__main__":
    main()
