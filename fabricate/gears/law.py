"""Ratio laws of non-circular gear pairs: formulas (evaluated safely), samples, the elliptic family.

A law maps the driving gear's angle ``x_a`` to the driven gear's angle ``x_b`` (rad, both relative to
the carrier) and is called like :class:`scipy.interpolate.CubicSpline`: ``law(x, nu)`` returns the
``nu``-th derivative. For an external pair ``law' < 0``; the transmission ratio is ``i = -law'``.

Formulas are strings in ``x`` such as ``"x + 0.03*sin(x)"``. They are parsed with :mod:`ast` and
evaluated by walking a whitelist of nodes (numbers, ``x``, ``pi``, ``e``, + - * / **, and the numpy
functions in :data:`FUNCTIONS`); nothing is passed to ``eval``. The whitelisted functions are analytic,
so the first derivative is taken by the complex step (exact to rounding) and higher ones by central
differences of it.
"""

from __future__ import annotations

import ast
import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np
from scipy.interpolate import CubicSpline

from fabricate.errors import SpecError

if TYPE_CHECKING:
    from fabricate.mechanism import Law

#: Functions a formula may call (all analytic, so the complex step differentiates them exactly).
FUNCTIONS: dict[str, Callable[[np.ndarray], np.ndarray]] = {
    "sin": np.sin, "cos": np.cos, "tan": np.tan, "exp": np.exp, "log": np.log, "sqrt": np.sqrt,
    "arctan": np.arctan, "atan": np.arctan, "arcsin": np.arcsin, "asin": np.arcsin,
    "arccos": np.arccos, "acos": np.arccos, "sinh": np.sinh, "cosh": np.cosh, "tanh": np.tanh,
}
CONSTANTS = {"pi": math.pi, "e": math.e}
_BINARY = {ast.Add: np.add, ast.Sub: np.subtract, ast.Mult: np.multiply, ast.Div: np.divide,
           ast.Pow: np.power}


def compile_formula(text: str, path: str = "law", variable: str = "x") -> Callable[[np.ndarray], np.ndarray]:
    """Compile a formula string into a numpy function of one array argument.

    Parameters
    ----------
    text : str
        E.g. ``"x + 0.03*sin(x)"``.
    path : str
        Field path for error messages.

    Raises
    ------
    SpecError
        On syntax errors or any name, call or operator outside the whitelist.
    """
    try:
        tree = ast.parse(text.strip(), mode="eval")
    except SyntaxError as exc:
        raise SpecError(path, f"invalid formula {text!r}: {exc.msg}") from exc

    def build(node: ast.AST) -> Callable[[np.ndarray], np.ndarray]:
        if isinstance(node, ast.Expression):
            return build(node.body)
        if isinstance(node, ast.Constant) and isinstance(node.value, (int, float)) \
                and not isinstance(node.value, bool):
            value = float(node.value)
            return lambda x: value + 0.0 * x
        if isinstance(node, ast.Name):
            if node.id == variable:
                return lambda x: x
            if node.id in CONSTANTS:
                value = CONSTANTS[node.id]
                return lambda x: value + 0.0 * x
            raise SpecError(path, f"unknown name {node.id!r} in {text!r} (use {variable}, pi, e)")
        if isinstance(node, ast.BinOp) and type(node.op) in _BINARY:
            op, left, right = _BINARY[type(node.op)], build(node.left), build(node.right)
            return lambda x: op(left(x), right(x))
        if isinstance(node, ast.UnaryOp) and isinstance(node.op, (ast.USub, ast.UAdd)):
            inner = build(node.operand)
            return (lambda x: -inner(x)) if isinstance(node.op, ast.USub) else inner
        if isinstance(node, ast.Call) and isinstance(node.func, ast.Name) and not node.keywords:
            if node.func.id not in FUNCTIONS:
                raise SpecError(path, f"function {node.func.id!r} is not allowed in {text!r}; "
                                      f"allowed: {', '.join(sorted(FUNCTIONS))}")
            if len(node.args) != 1:
                raise SpecError(path, f"{node.func.id}() takes one argument in {text!r}")
            fn, arg = FUNCTIONS[node.func.id], build(node.args[0])
            return lambda x: fn(arg(x))
        raise SpecError(path, f"unsupported expression {ast.dump(node)[:40]}... in {text!r}")

    return build(tree)


@dataclass(frozen=True)
class FormulaLaw:
    """``x_b = sign * g(x_a)`` for a formula ``g``; ``sign=-1`` turns a driven-angle formula into an
    external pair's law (the gears turn opposite ways relative to the carrier).

    Derivatives: ``nu=1`` by the complex step; ``nu=2, 3`` by central differences of ``nu=1``
    (step 1e-4 rad: truncation ~1e-9, rounding ~1e-12 relative).
    """

    text: str
    sign: float = -1.0
    path: str = "law"
    _fn: Callable[[np.ndarray], np.ndarray] = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "_fn", compile_formula(self.text, self.path))

    def _slope(self, x: np.ndarray) -> np.ndarray:
        h = 1e-30
        with np.errstate(all="ignore"):
            return np.imag(self._fn(x + 1j * h)) / h

    def __call__(self, x: np.ndarray | float, nu: int = 0) -> np.ndarray | float:
        x = np.asarray(x, dtype=np.float64)
        with np.errstate(all="ignore"):
            if nu == 0:
                out = self._fn(x)
            elif nu == 1:
                out = self._slope(x)
            elif nu == 2:
                h = 1e-4
                out = (self._slope(x + h) - self._slope(x - h)) / (2 * h)
            elif nu == 3:
                h = 1e-3
                out = (self._slope(x + h) - 2 * self._slope(x) + self._slope(x - h)) / (h * h)
            else:
                raise ValueError("derivatives up to nu=3 are supported")
        return self.sign * np.real(out) + 0.0 * x


def elliptic_formula(eccentricity: float) -> str:
    """Driven-angle formula of two equal ellipses turning about their foci (ratio 1:1 over a turn).

    With k = (1-e)/(1+e) the classical law is psi = 2 atan(k tan(x/2)); rewritten without the branch
    jump at x = pi as psi = x - 2 atan(e sin x / (1 + e cos x)). Its slope is
    (1 - e^2) / (1 + e^2 + 2 e cos x), so the driving pitch radius at x = 0 is A (1 - e).
    """
    e = float(eccentricity)
    return f"x - 2*arctan({e!r}*sin(x)/(1 + {e!r}*cos(x)))"


def elliptic_law(eccentricity: float) -> FormulaLaw:
    """External-pair law of the 1:1 elliptic family (see :func:`elliptic_formula`)."""
    if not 0.0 <= eccentricity < 1.0:
        raise SpecError("gear_pair.eccentricity", f"expected 0 <= e < 1, got {eccentricity:g}")
    return FormulaLaw(elliptic_formula(eccentricity), sign=-1.0)


def samples_law(x_a: np.ndarray, x_b: np.ndarray, path: str = "law_samples") -> CubicSpline:
    """Cubic spline through law samples (rad); rejects unsorted or non-finite samples."""
    x_a = np.asarray(x_a, dtype=np.float64)
    x_b = np.asarray(x_b, dtype=np.float64)
    if len(x_a) < 3:
        raise SpecError(path, f"expected at least 3 samples, got {len(x_a)}")
    if not (np.all(np.isfinite(x_a)) and np.all(np.isfinite(x_b))):
        raise SpecError(path, "samples must be finite")
    if np.any(np.diff(x_a) <= 0):
        raise SpecError(path, "driving angles must increase strictly")
    return CubicSpline(x_a, x_b)


def law_derivative(law: Law, x: np.ndarray, nu: int) -> np.ndarray:
    """``law(x, nu)`` as a float array; falls back to central differences of ``nu-1`` when the law
    does not provide that derivative (e.g. ``nu=3`` of a user callable)."""
    x = np.asarray(x, dtype=np.float64)
    try:
        out = np.asarray(law(x, nu), dtype=np.float64)
        if out.shape == x.shape:
            return out
    except (TypeError, ValueError):
        pass
    h = 1e-4
    central: np.ndarray = (law_derivative(law, x + h, nu - 1) - law_derivative(law, x - h, nu - 1)) / (2 * h)
    return central


def check_ratio(law: Law, x: np.ndarray, path: str = "law") -> np.ndarray:
    """Transmission ratio ``i = -law'(x)`` on ``x``; raises when it is not finite or not positive.

    Raises
    ------
    SpecError
        Naming the angle where the ratio fails and the fix.
    """
    ratio = -law_derivative(law, x, 1)
    # the law itself too: the complex step can give a finite slope where the real value is NaN
    bad = ~np.isfinite(ratio) | ~np.isfinite(np.asarray(law(x), dtype=np.float64))
    if np.any(bad):
        at = float(np.degrees(x[np.argmax(bad)]))
        raise SpecError(path, f"the law or its ratio is not finite at x_a = {at:.3f} deg; "
                              "give a law that is smooth over the working range")
    if np.any(ratio <= 0):
        k = int(np.argmin(ratio))
        raise SpecError(path, f"transmission ratio {ratio[k]:.4g} <= 0 at x_a = {np.degrees(x[k]):.3f} deg: "
                              "an external gear pair needs the driven angle to change monotonically "
                              "with the driving angle; use a monotonic law (ratio > 0 everywhere)")
    return ratio
