"""Template tables of the five-bar NCG finger (kind ``five_bar_ncg``): ``[finger]`` and ``[synthesis]`` -> a
frozen :class:`FiveBarSpec`, and its cost estimate (:func:`preflight`)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from fabricate.bounds import MAX_KAPPA_SAMPLES, MAX_LENGTH_MM, MIN_CURVE_STEP_MM
from fabricate.errors import SpecError
from fabricate.table import Table

if TYPE_CHECKING:
    from fabricate.spec import DesignSpec

#: Rules for picking one dyad of the feasible domain.
SELECTION_RULES = ("x_A", "least_pose_error")
#: Minimum number of poses: with fewer, the four smallest eigenvectors of M^T M span an arbitrary
#: part of a larger null space and the family is not determined by the poses.
MIN_POSES = 4
#: Most target poses (each adds a row to the constraint matrix and a knot to the gear law).
MAX_POSES = 100


@dataclass(frozen=True)
class FiveBarSpec:
    """``[finger]`` and ``[synthesis]`` of a five_bar_ncg template. Lengths mm, angles deg.

    Attributes
    ----------
    lengths_mm : (float, float, float)
        Phalanx lengths O-D, D-C, C-P (Table 1).
    origin_mm : (float, float)
        Position of the base joint O.
    poses_deg : tuple of (float, float, float)
        Absolute angles of the three phalanges from +x at every target pose, in motion order.
    pad_radius_mm : float
        Fingertip pad radius (a parts hint).
    kappa_samples : int
        Samples of ``omega`` in (0, pi) for tracing the hinge curves.
    curve_step_mm : float
        Largest step of A or B between samples inside the A box (more samples are inserted there).
    a_x_mm, a_y_mm : (float, float)
        Box for hinge A at the first pose.
    ab_length_mm, bc_length_mm : (float, float)
        Allowed lengths of A-B and B-C.
    max_length_error_mm : float
        Largest allowed change of |AB| over the target poses (the dyad's error, eq 16's cause).
    transmission_ratio : (float, float)
        Allowed range of the gear ratio ``i = -dx_b / dx_a`` over the working range.
    min_pitch_curvature_radius_mm : float
        Both pitch curves must be convex with at least this radius of curvature.
    select : str
        ``"x_A"`` (the feasible dyad whose A has x = ``x_A_mm``; least length error among several)
        or ``"least_pose_error"``.
    x_A_mm : float or None
    """

    lengths_mm: tuple[float, float, float]
    origin_mm: tuple[float, float]
    poses_deg: tuple[tuple[float, float, float], ...]
    pad_radius_mm: float
    kappa_samples: int
    curve_step_mm: float
    a_x_mm: tuple[float, float]
    a_y_mm: tuple[float, float]
    ab_length_mm: tuple[float, float]
    bc_length_mm: tuple[float, float]
    max_length_error_mm: float
    transmission_ratio: tuple[float, float]
    min_pitch_curvature_radius_mm: float
    select: str
    x_A_mm: float | None


def _interval(table: Table, key: str, default: Any = None, *, positive: bool = False,
              bound: float = MAX_LENGTH_MM) -> tuple[float, float]:
    arr = table.array(key, default, shape=(2,), positive=positive, min=-bound, max=bound) if default is not None \
        else table.array(key, shape=(2,), positive=positive, min=-bound, max=bound)
    arr = np.asarray(arr, dtype=np.float64)
    if not arr[0] < arr[1]:
        raise SpecError(table.field(key), f"expected [low, high] with low < high, got {arr.tolist()}")
    return float(arr[0]), float(arr[1])


def parse_spec(root: Table) -> FiveBarSpec:
    """Read ``[finger]`` and ``[synthesis]`` from a template root.

    Raises
    ------
    SpecError
        Naming the field: fewer than four poses, a proximal angle that does not change monotonically,
        empty ranges, a selection rule without its target.
    """
    finger = root.table("finger")
    # magnitudes and counts are bounded (fabricate.bounds): a 1e300 mm phalanx overflows the mapping
    lengths = finger.array("lengths_mm", shape=(3,), positive=True, max=MAX_LENGTH_MM)
    origin = finger.array("origin_mm", [0.0, 0.0], shape=(2,), min=-MAX_LENGTH_MM, max=MAX_LENGTH_MM)
    poses = finger.array("poses_deg", shape=(None, 3), min_rows=MIN_POSES, min=-720.0, max=720.0)
    if len(poses) > MAX_POSES:
        raise SpecError(finger.field("poses_deg"), f"{len(poses)} poses, over the bound of {MAX_POSES}")
    pad = finger.number("pad_radius_mm", 5.0, positive=True, max=200.0)
    finger.finish()
    proximal = np.diff(np.unwrap(np.radians(poses[:, 0])))
    if not (np.all(proximal > 0) or np.all(proximal < 0)):
        raise SpecError(finger.field("poses_deg"),
                        "the proximal angle (first column) must change strictly monotonically over the poses")
    syn = root.table("synthesis")
    spec = FiveBarSpec(
        lengths_mm=(float(lengths[0]), float(lengths[1]), float(lengths[2])),
        origin_mm=(float(origin[0]), float(origin[1])),
        poses_deg=tuple((float(row[0]), float(row[1]), float(row[2])) for row in poses),
        pad_radius_mm=pad,
        kappa_samples=syn.integer("kappa_samples", 2001, min=50, max=MAX_KAPPA_SAMPLES),
        curve_step_mm=syn.number("curve_step_mm", 0.25, min=MIN_CURVE_STEP_MM, max=MAX_LENGTH_MM),
        a_x_mm=_interval(syn, "a_x_mm"),
        a_y_mm=_interval(syn, "a_y_mm"),
        ab_length_mm=_interval(syn, "ab_length_mm", positive=True),
        bc_length_mm=_interval(syn, "bc_length_mm", positive=True),
        max_length_error_mm=syn.number("max_length_error_mm", 0.5, positive=True, max=MAX_LENGTH_MM),
        transmission_ratio=_interval(syn, "transmission_ratio", [0.2, 5.0], positive=True, bound=1000.0),
        min_pitch_curvature_radius_mm=syn.number("min_pitch_curvature_radius_mm", 2.0, min=0.0, max=MAX_LENGTH_MM),
        select=syn.string("select", "least_pose_error", choices=SELECTION_RULES),
        x_A_mm=syn.number("x_A_mm", None, min=-MAX_LENGTH_MM, max=MAX_LENGTH_MM),
    )
    if spec.select == "x_A" and spec.x_A_mm is None:
        raise SpecError(syn.field("x_A_mm"), 'missing required field (select = "x_A" needs it)')
    syn.finish()
    return spec


def preflight(design: DesignSpec) -> None:
    """Nothing to estimate: no product of this kind's counts is bounded beyond its fields.

    The synthesis's work grows with the poses (at most :data:`MAX_POSES`), the hinge-curve samples
    (``synthesis.kappa_samples``, at most :data:`~fabricate.bounds.MAX_KAPPA_SAMPLES`) and the refinement step
    (``synthesis.curve_step_mm``, at least :data:`~fabricate.bounds.MIN_CURVE_STEP_MM`), each bounded by its
    parser.
    """
