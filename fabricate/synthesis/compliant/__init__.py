"""Compliant three-finger gripper with two spring hinges per finger (seed 003), kind ``compliant_gripper``.

Reads ``[finger]``, ``[springs]``, ``[object]``, ``[optimisation]`` and ``[drive]``; computes

- the grasp of the paper's procedure (:func:`fabricate.synthesis.compliant.model.solve_grasp`): the
  stroke where the hover force reaches F_n2 = mg/(3 mu s), and F_n1 at that stroke, on the physical
  branch (tip turned in on the can, two-force rod pushing);
- the grasp force against stroke (paper Fig 3);
- the certified optimum of Delta N over the Table 1 grid (:mod:`fabricate.synthesis.compliant.grid_search`);
- the no-load closing (eqs 1-2: least spring energy at each stroke with the hinges on their stops
  until the rod overcomes the preloads), continued on the can up to the grasp stroke;

and returns one finger's planar :class:`~fabricate.mechanism.Mechanism` driven by the drive rod: a
slider with a "slide" driver over the stroke, the root phalanx held at alpha by an "angle" driver
(in the gripper the root push rod sets it), and the one hinge angle the drive does not fix as an
"angle" driver whose law (monotone cubic, stroke -> angle) comes from the closing solution.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.interpolate import PchipInterpolator
from scipy.optimize import brentq, fsolve

from fabricate.bounds import (
    MAX_GRID_AXIS,
    MAX_LENGTH_MM,
    MAX_PATH_SAMPLES,
    MAX_SPRING_RATE,
)
from fabricate.errors import SpecError, SynthesisError
from fabricate.mechanism import Body, Driver, LinearLaw, Mechanism, Revolute, Slider
from fabricate.synthesis.base import SynthesisResult
from fabricate.synthesis.compliant.grid_search import OptimumResult, ParameterGrid, optimise
from fabricate.synthesis.compliant.model import (
    ContactPath,
    Grasp,
    GripperGeometry,
    Load,
    Springs,
    contact_path,
    finger_state,
    grasp_force_curve,
    phi1_on_can,
    solve_grasp,
    spring_torques,
)
from fabricate.table import Table


@dataclass(frozen=True)
class CompliantSpec:
    """Validated template of the compliant gripper (mm, rad, N·mm/deg springs)."""

    geometry: GripperGeometry
    springs: Springs
    load: Load
    pad_arc: float
    grid: ParameterGrid | None
    min_hinge: float
    path_samples: int
    spring_legs: float
    overtravel: float
    fingers: int


def _grid_axis(table: Table, key: str, scale: float, lo: float, hi: float) -> np.ndarray:
    start, stop, step = table.array(key, shape=(3,), min=lo, max=hi)
    if step <= 0 or stop < start:
        raise SpecError(table.field(key), "expected [start, stop, step] with step > 0 and stop >= start")
    count = int(np.floor((stop - start) / step + 1e-9)) + 1
    if count > MAX_GRID_AXIS:  # checked before the axis is made (a step of 1e-300 would not fit memory)
        raise SpecError(table.field(key), f"{count} grid values, over the bound of {MAX_GRID_AXIS}; use a larger step")
    return (start + step * np.arange(count)) * scale


def parse_spec(root: Table) -> CompliantSpec:
    """Read ``[finger]``, ``[springs]``, ``[object]``, ``[optimisation]``, ``[drive]``."""
    f = root.table("finger")
    geom = GripperGeometry(
        a1=f.number("a1_mm", positive=True, max=MAX_LENGTH_MM), a2=f.number("a2_mm", positive=True, max=MAX_LENGTH_MM),
        a3=f.number("a3_mm", positive=True, max=MAX_LENGTH_MM), b=f.number("b_mm", min=0.0, max=MAX_LENGTH_MM),
        c=f.number("c_mm", min=0.0, max=MAX_LENGTH_MM),
        d=f.number("d_mm", positive=True, max=MAX_LENGTH_MM),
        l1=f.number("l1_mm", positive=True, max=MAX_LENGTH_MM),
        l2=f.number("l2_mm", positive=True, max=MAX_LENGTH_MM),
        r=f.number("pad_radius_mm", positive=True, max=MAX_LENGTH_MM),
        alpha=np.radians(f.number("alpha_deg", min=0.0, max=90.0)))
    pad_arc = np.radians(f.number("pad_arc_deg", 90.0, positive=True, max=180.0))
    f.finish()
    s = root.table("springs")
    springs = Springs(k1=s.number("k1_Nmm_per_deg", min=0.0, max=MAX_SPRING_RATE),
                      k2=s.number("k2_Nmm_per_deg", min=0.0, max=MAX_SPRING_RATE),
                      phi01=s.number("phi01_rad", min=0.0, max=2 * np.pi),
                      phi02=s.number("phi02_rad", min=0.0, max=2 * np.pi))
    legs = s.number("legs_mm", 20.0, positive=True, max=MAX_LENGTH_MM)
    s.finish()
    o = root.table("object")
    load = Load(diameter=o.number("diameter_mm", positive=True, max=MAX_LENGTH_MM),
                mass=o.number("mass_kg", positive=True, max=1000.0),
                mu=o.number("friction", positive=True, max=2.0), safety=o.number("safety", positive=True, max=100.0),
                g=o.number("gravity", 9.8, positive=True, max=100.0))
    o.finish()
    opt = root.table("optimisation", {})
    enabled = opt.boolean("enabled", True)
    grid = None
    if opt.has("alpha_deg") or enabled:
        grid = ParameterGrid(
            alpha=_grid_axis(opt, "alpha_deg", np.pi / 180.0, 0.0, 90.0),
            c=_grid_axis(opt, "c_mm", 1.0, 0.0, 500.0),
            k1=_grid_axis(opt, "k1_Nmm_per_deg", 1.0, 0.0, 1e4),
            k2=_grid_axis(opt, "k2_Nmm_per_deg", 1.0, 0.0, 1e4),
            phi01=_grid_axis(opt, "phi01_deg", np.pi / 180.0, 0.0, 360.0),
            phi02=_grid_axis(opt, "phi02_deg", np.pi / 180.0, 0.0, 360.0))
    if not enabled:
        grid = None
    min_hinge = np.radians(opt.number("min_hinge_deg", 5.0, min=0.0, max=45.0))
    samples = opt.integer("path_samples", 181, min=31, max=MAX_PATH_SAMPLES)
    opt.finish()
    dr = root.table("drive", {})
    overtravel = dr.number("overtravel_mm", 1.0, min=0.0, max=MAX_LENGTH_MM)
    fingers = dr.integer("fingers", 3, min=1, max=12)
    dr.finish()
    return CompliantSpec(geom, springs, load, pad_arc, grid, min_hinge, samples, legs, overtravel, fingers)


# -- closing motion ------------------------------------------------------------------------------

@dataclass(frozen=True)
class GripperMotion:
    """Hinge angles (rad) against stroke (mm) from the open finger to the end of the sweep."""

    strokes: np.ndarray
    phi1: np.ndarray
    phi2: np.ndarray
    on_can: np.ndarray


def _no_load_residual(geom: GripperGeometry, springs: Springs, x: np.ndarray, s: float) -> np.ndarray:
    st = finger_state(geom, x[0], x[1])
    s1, s2 = spring_torques(springs, x[0], x[1])
    # eqs 1-2 with Fd eliminated: s1 h2 - s2 h1 = 0; scaled so both rows are about mm
    return np.array([float(st.stroke) - s, float(s1 * st.h2 - s2 * st.h1) / 1e3])


def no_load_closing(geom: GripperGeometry, springs: Springs, strokes: np.ndarray) -> np.ndarray:
    """Eqs 1-2 over increasing strokes with the hinge stops (phi >= 0) as an active set.

    A hinge stays on its stop while the rod's moment about it is below the spring preload (the stop
    still pushes back); then both hinges are free and eqs 1-2 hold (Fd eliminated). On a stop the
    other hinge follows the stroke alone (a 1-D root). Returns (m, 2) angles (phi1, phi2), rad.
    """
    out = np.zeros((len(strokes), 2))
    x = np.zeros(2)
    mode = None
    for i, s in enumerate(strokes):
        if s <= 0.0:
            continue
        for _ in range(3):
            if mode is None or mode in ("B", "C"):
                candidates = [mode] if mode else ["B", "C"]
                solved = None
                for m in candidates:
                    j = 0 if m == "B" else 1           # the hinge that moves
                    def one(v, j=j, s=s):
                        y = np.zeros(2)
                        y[j] = v
                        return float(finger_state(geom, y[0], y[1]).stroke) - s
                    grid = np.linspace(x[j], np.pi, 721)
                    vals = finger_state(geom, *(np.where(np.arange(2)[:, None] == j, grid, 0.0))).stroke - s
                    sign = np.nonzero(np.sign(vals[:-1]) != np.sign(vals[1:]))[0]
                    if sign.size == 0:
                        continue
                    v = brentq(one, grid[sign[0]], grid[sign[0] + 1], xtol=1e-14)
                    y = np.zeros(2)
                    y[j] = v
                    st = finger_state(geom, y[0], y[1])
                    s1, s2 = spring_torques(springs, y[0], y[1])
                    h_move, h_stop = (st.h1, st.h2) if m == "B" else (st.h2, st.h1)
                    t_move, t_stop = (s1, s2) if m == "B" else (s2, s1)
                    fd = t_move / h_move if h_move != 0 else 0.0
                    if t_stop - fd * h_stop >= -1e-9:      # the stop still holds
                        solved = (m, y)
                        break
                if solved is not None:
                    mode, x = solved
                    break
                mode = "free"
            if mode == "free":
                y, info, ok, _ = fsolve(lambda v, s=s: _no_load_residual(geom, springs, v, s), x,
                                        full_output=True, xtol=1e-13)
                if ok == 1 and y[0] >= -1e-9 and y[1] >= -1e-9:
                    x = np.maximum(y, 0.0)
                    break
                mode = "B" if y[1] < 0 else "C"
        else:
            raise SynthesisError(f"compliant_gripper: no-load closing lost at stroke {s:.3f} mm")
        if abs(float(finger_state(geom, x[0], x[1]).stroke) - s) > 1e-6:
            raise SynthesisError(f"compliant_gripper: no-load closing lost at stroke {s:.3f} mm")
        out[i] = x
    return out


def closing_motion(spec: CompliantSpec, path: ContactPath, grasp: Grasp, samples: int = 81) -> GripperMotion:
    """Free closing up to the first touch, then on the can up to the grasp stroke plus overtravel."""
    geom = spec.geometry
    end = grasp.stroke + spec.overtravel
    strokes = np.linspace(0.0, end, samples)
    free = strokes <= grasp.contact_stroke
    phi = np.zeros((samples, 2))
    phi[free] = no_load_closing(geom, spec.springs, strokes[free])
    st = path.state
    for i in np.nonzero(~free)[0]:
        s = strokes[i]
        j = int(np.searchsorted(st.stroke, s))
        if j <= 0 or j >= len(st.stroke):
            raise SynthesisError(f"compliant_gripper: stroke {s:.2f} mm leaves the contact path")
        p2 = brentq(lambda v, s=s: float(finger_state(geom, phi1_on_can(geom, v, path.can_radius), v).stroke) - s,
                    path.phi2[j - 1], path.phi2[j], xtol=1e-14)
        phi[i] = (float(phi1_on_can(geom, p2, path.can_radius)), p2)
    return GripperMotion(strokes, phi[:, 0], phi[:, 1], ~free)


# -- mechanism -----------------------------------------------------------------------------------

def build_mechanism(spec: CompliantSpec, motion: GripperMotion, name: str) -> Mechanism:
    """One finger: palm (ground), root, middle, tip, two-force rod, drive rod (slider)."""
    g = spec.geometry
    st0 = finger_state(g, 0.0, 0.0)
    m0 = st0.M
    bodies = (
        Body("palm", {"A": (0.0, 0.0), "drive": (g.l2, float(m0[1]) + 30.0),
                      "palm_centre": (-g.l1, 0.0)}),
        Body("root", {"A": (0.0, 0.0), "B": (g.a1, 0.0)}),
        Body("middle", {"B": (0.0, 0.0), "C": (g.a2, 0.0)}),
        Body("tip", {"C": (0.0, 0.0), "D": (g.a3, 0.0), "E": (g.a3, g.c), "pad": (g.a3 + g.b, g.r),
                     "pad_start": (g.a3 + g.b, 0.0), "tip": (g.a3 + g.b + g.r, g.r)}),
        Body("two_force_rod", {"E": (0.0, 0.0), "M": (g.d, 0.0)}),
        Body("drive_rod", {"M": (0.0, 0.0), "drive": (0.0, 30.0)}),
    )
    joints = (Revolute("A", "palm", "root"), Revolute("B", "root", "middle"), Revolute("C", "middle", "tip"),
              Revolute("E", "tip", "two_force_rod"), Revolute("M", "two_force_rod", "drive_rod"),
              Slider("drive", "palm", "drive_rod", (0.0, -1.0)))
    # choose which hinge to prescribe: the other one is solved from the stroke, so it must keep the
    # stroke sensitive to it (the rod must not pass through that hinge)
    st = finger_state(g, motion.phi1, motion.phi2)
    sens_phi2, sens_phi1 = np.abs(st.h2).min(), np.abs(st.h1).min()
    if sens_phi2 >= sens_phi1:
        driver = Driver("angle", "tip", "middle", law=PchipInterpolator(motion.strokes, -motion.phi1))
    else:
        driver = Driver("angle", "middle", "root", law=PchipInterpolator(motion.strokes, -motion.phi2))
    drivers = (Driver("slide", "drive_rod", "palm", joint="drive"),
               Driver("angle", "root", "palm", law=LinearLaw(0.0, -g.alpha)), driver)
    e = np.array([np.cos(g.alpha), -np.sin(g.alpha)])
    e_vec = st0.E
    rod_dir = m0 - e_vec
    assembly = {"root": (0.0, 0.0, -g.alpha), "middle": (*(g.a1 * e), -g.alpha),
                "tip": (*((g.a1 + g.a2) * e), -g.alpha),
                "two_force_rod": (float(e_vec[0]), float(e_vec[1]), float(np.arctan2(rod_dir[1], rod_dir[0]))),
                "drive_rod": (float(m0[0]), float(m0[1]), 0.0)}
    return Mechanism(name=name, bodies=bodies, ground="palm", joints=joints, gears=(), drivers=drivers,
                     input_range=(0.0, float(motion.strokes[-1])), input_unit="mm", assembly=assembly)


# -- synthesis -----------------------------------------------------------------------------------

#: Drive parts shared by all fingers (paper Fig 1): two lead-screw steppers move the tip and root
#: drive plates along two guide posts.
DRIVE_PARTS = (
    {"item": "stepper motor with lead screw", "qty": 2, "note": "tip drive (1) and root drive (2), Fig 1"},
    {"item": "guide post", "qty": 2, "note": "joins the motor plate and the finger-base plate (4)"},
    {"item": "linear bearing", "qty": 4, "note": "each guide post through both drive plates (5)"},
    {"item": "lead-screw nut", "qty": 2, "note": "one per drive plate (8)"},
    {"item": "lead-screw support bearing", "qty": 2, "note": "in the finger-base plate (12)"},
)

def paper_point(spec: CompliantSpec) -> tuple[ContactPath, Grasp]:
    """Grasp of the template's own parameters (the paper's optimum in the shipped template)."""
    path = contact_path(spec.geometry, spec.load.radius, spec.load.mu, n=max(spec.path_samples, 721),
                        pad_arc=spec.pad_arc)
    grasp = solve_grasp(path, spec.springs, spec.load)
    if grasp is None:
        raise SynthesisError("compliant_gripper: the hover force never reaches F_n2 = mg/(3 mu s) on the "
                             "physical branch (finger closing on the can, rod pushing)")
    return path, grasp


def _optimum_report(spec: CompliantSpec, result: OptimumResult) -> dict:
    g = spec.geometry
    geom = GripperGeometry(g.a1, g.a2, g.a3, g.b, result.c, g.d, g.l1, g.l2, g.r, result.alpha)
    springs = Springs(result.k1, result.k2, result.phi01, result.phi02)
    path = contact_path(geom, spec.load.radius, spec.load.mu, n=1441, pad_arc=spec.pad_arc)
    exact = solve_grasp(path, springs, spec.load)
    return {
        "alpha_rad": result.alpha, "c_mm": result.c, "k1": result.k1, "k2": result.k2,
        "phi01_rad": result.phi01, "phi02_rad": result.phi02,
        "delta_N_N": exact.delta_n if exact is not None else result.delta_n,
        "F_n1_N": exact.fn_static if exact is not None else None,
        "stroke_mm": exact.stroke if exact is not None else None,
        "grid_delta_N_N": result.delta_n,
        "certificate": {
            "grid_points": result.grid_points, "points_enumerated": result.points_evaluated,
            "paths": result.paths, "paths_searched": result.paths_searched,
            "intervals": result.intervals, "intervals_searched": result.intervals_searched,
            "points_verified": result.points_verified, "lower_bound_N": result.lower_bound,
            "pruned_bound_N": result.pruned_bound,
            "path_samples": spec.path_samples, "min_hinge_deg": float(np.degrees(spec.min_hinge)),
            "method": "exact lower bound of Delta N per (alpha, c, path interval); intervals below the "
                      "incumbent searched in bound order, every grid point crossing there valued exactly "
                      "(phi02 ranges from the running minimum of the hover threshold); the rest is "
                      "bounded by pruned_bound_N >= the optimum"},
    }


def synthesise(design) -> SynthesisResult:
    """Grasp, Fig-3 curve, optimum, closing motion, mechanism and parts hints."""
    spec: CompliantSpec = design.method
    path, grasp = paper_point(spec)
    strokes, f_static, f_hover = grasp_force_curve(path, spec.springs, spec.load.mu)
    motion = closing_motion(spec, path, grasp)
    mech = build_mechanism(spec, motion, design.name)
    st = finger_state(spec.geometry, grasp.phi1, grasp.phi2)
    s1, s2 = spring_torques(spec.springs, grasp.phi1, grasp.phi2)
    report = {
        "F_n2_N": spec.load.hover_force,
        "paper_optimum": {"F_n1_N": grasp.fn_static, "F_n2_N": grasp.fn_hover, "delta_N_N": grasp.delta_n},
        "paper_printed": {"F_n1_N": 4.50, "F_n2_N": 3.78, "delta_N_N": 0.72,
                          "note": "read off the paper's Fig 3; eqs 3-6 at the hover pose give F_n1 above"},
        "grasp": {"stroke_mm": grasp.stroke, "first_touch_stroke_mm": grasp.contact_stroke,
                  "phi1_deg": float(np.degrees(grasp.phi1)), "phi2_deg": float(np.degrees(grasp.phi2)),
                  "rod_force_static_N": grasp.fd_static, "rod_force_hover_N": grasp.fd_hover,
                  "beta_deg": float(np.degrees(st.beta)), "gamma_deg": float(np.degrees(st.gamma)),
                  "spring_torques_Nmm": [float(s1), float(s2)]},
        "grasp_force_curve": {"stroke_mm": strokes[::10].tolist(), "F_static_N": f_static[::10].tolist(),
                              "F_hover_N": f_hover[::10].tolist()},
        "fingers": spec.fingers,
        "drive_parts": [dict(item) for item in DRIVE_PARTS],
    }
    optimum = None
    if spec.grid is not None:
        optimum = optimise(spec.geometry, spec.grid, spec.load, samples=spec.path_samples,
                           hinge_margin=spec.min_hinge)
        report["optimum"] = _optimum_report(spec, optimum)
    g = spec.geometry
    parts = {
        "springs": [
            {"joint": "C", "rate_Nmm_per_deg": spec.springs.k1, "preload_deg": float(np.degrees(spec.springs.phi01)),
             "legs_mm": spec.spring_legs, "note": "small torsion spring, tip hinge (k1)"},
            {"joint": "B", "rate_Nmm_per_deg": spec.springs.k2, "preload_deg": float(np.degrees(spec.springs.phi02)),
             "legs_mm": spec.spring_legs, "note": "large torsion spring, middle hinge (k2)"},
        ],
        # the fingertip arc of radius r runs from its tangent point on the phalanx to the tip
        "pads": {"tip": {"point": "pad", "radius_mm": g.r, "arc": ["pad_start", "tip"]}},
        # per finger (the BOM layer multiplies these by "copies")
        "purchased": [
            {"item": "tip drive rod, 4 mm steel, threaded end", "qty": 1, "note": "pushes the two-force rod"},
            {"item": "root push rod, 4 mm steel, threaded end", "qty": 1, "note": "sets the root angle alpha"},
            {"item": "adjusting knob", "qty": 1, "note": "sets the tip spring preload"},
        ],
        # once per gripper, shared by the fingers: listed apart so they are not multiplied
        "purchased_shared": list(DRIVE_PARTS),
        "copies": spec.fingers,
        "copy_angle_deg": 360.0 / spec.fingers,
        "tip_point": "tip",
    }

    def figures() -> dict[str, bytes]:
        from fabricate.synthesis.compliant.plots import compliant_figures
        return compliant_figures(spec, path, grasp, motion, optimum)

    data = {"path": path, "grasp": grasp, "motion": motion, "optimum": optimum,
            "force_curve": (strokes, f_static, f_hover)}
    return SynthesisResult(mechanism=mech, report=report, figures=figures, data=data, parts=parts)
