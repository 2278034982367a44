"""The virtual rack both gears are cut by, and the envelope (exact and osculating-circle) mappings.

Rack coordinates ``(u, v)``: ``u`` along the pitch line (mm, the rolled arc length), ``v`` across it,
positive towards gear b. One profile line separates gear-a material (below) from gear-b material
(above): a trapezoid wave of period ``p = pi m`` with straight flanks at the pressure angle, flats at
``v = -h_f`` (gear a's root) and ``v = +h_f`` (gear b's root) and round corners of radius
``rho_f``, so each gear's cutter is the complement of the other gear's teeth (the basic rack).

Envelope (theory of gearing): a rack point ``c`` with unit normal ``nu`` touches the gear it cuts when
its normal passes through the pitch point, which sits at rack abscissa ``s``:
``s = c_u - c_v nu_u / nu_v``. There the rack lies along the pitch tangent, so the gear-frame point is
``P(s) + (c_u - s) t(s) + c_v n(s)`` (gear b: ``-c_v``, its outward normal points the other way).
Because every profile point maps to exactly one gear point, the tooth outline comes out in order and
its vertices are exact (no simulated-cutting scallops). Both gears are enveloped by the same rack,
hence they are conjugate (Camus) and roll with zero transmission error except for backlash.

Backlash: each gear's profile is offset by ``delta = j cos(alpha) / 4`` along the normal into its own
material, a true normal offset of lines and arcs (arcs change radius by ``delta``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fabricate.gears.pitch import PitchFrames

#: Element labels of the rack profile.
FLAT_ROOT_A, ROUND_ROOT_A, FLANK = range(3)


@dataclass(frozen=True)
class RackProfile:
    """The cutter of one gear over one period, ``u`` in [-p/2, p/2), that gear's tooth centred at 0.

    Only the part the gear can see is kept: its root flat and fillet round, and the straight flank
    extended a little past the gear's tip (the other gear's root corner lies beyond the tip curve
    and, being concave for this cutter, would only add envelope loops that the tip clip removes).

    Attributes
    ----------
    points : (k, 2) array
        Profile points (u, v), mm, in order of increasing u.
    normals : (k, 2) array
        Unit normals pointing into gear-b material (so out of gear a, into gear b).
    element : (k,) int array
        Element label (see module constants).
    flank_u : (k,) array
        Pitch-line abscissa of the flank a point belongs to (``-p/4`` left, ``+p/4`` right, NaN
        elsewhere).
    pitch : float
        Circular pitch ``p = pi m``.
    """

    points: np.ndarray
    normals: np.ndarray
    element: np.ndarray
    flank_u: np.ndarray
    pitch: float

    def for_gear_b(self) -> RackProfile:
        """Gear b's cutter: gear a's reflected across the pitch line (a b tooth centred at 0).

        Reflection maps gear a's left flank ``u = -p/4 + v tan(alpha)`` onto the line
        ``u = -p/4 - v tan(alpha)``, which, shifted by half a pitch to the b tooth's centre, is gear
        a's right flank: both gears are enveloped by the same rack lines.
        """
        pts = self.points * [1.0, -1.0]
        normals = self.normals * [-1.0, 1.0]
        return RackProfile(pts, normals, self.element, self.flank_u, self.pitch)


#: Smallest half-width (× module) of the cutter's tip flat (the gear's root flat) kept by
#: :func:`rack_fit`: below it the flat degenerates to a point and the round corners would cross.
MIN_ROOT_LAND = 0.02


def rack_fit(pressure_angle: float, dedendum: float) -> tuple[float, float]:
    """Largest dedendum and root fillet (× module) the rack tooth space holds at ``pressure_angle``.

    The flank of gear a's cutter crosses the root line ``v = -h_f`` at ``u = -p/4 - h_f tan(alpha)``;
    the cutter's tip flat (gear a's root) must keep a half-width of :data:`MIN_ROOT_LAND` before the
    half period ``-p/2``, so ``h_f <= (pi/4 - land) / tan(alpha)``. A round of radius ``rho``
    tangent to the flat and the flank has its centre at ``u = -p/4 + ((rho - h_f) sin(alpha) - rho) /
    cos(alpha)`` (see :func:`basic_rack`), which gives the largest radius for a dedendum.

    Parameters
    ----------
    pressure_angle : float
        rad, in (0, pi/2).
    dedendum : float
        The wanted dedendum × module.

    Returns
    -------
    (float, float)
        ``(max_dedendum, max_root_fillet)``: the deepest root the tooth space holds at all, and the
        largest fillet for ``min(dedendum, max_dedendum)`` (0 when none fits), both × module.
    """
    sa, ca = np.sin(pressure_angle), np.cos(pressure_angle)
    quarter = np.pi / 4
    max_dedendum = (quarter - MIN_ROOT_LAND) * ca / sa
    hf = min(dedendum, max_dedendum)
    rho = (quarter * ca - MIN_ROOT_LAND * ca - hf * sa) / (1.0 - sa)
    return float(max_dedendum), float(min(max(rho, 0.0), hf))


def basic_rack(module: float, pressure_angle: float, dedendum: float, root_fillet: float,
               addendum: float = 1.0, flank_points: int = 241, round_points: int = 25,
               flat_points: int = 5) -> RackProfile:
    """Sample gear a's cutter over one period (gear b's: :meth:`RackProfile.for_gear_b`).

    Parameters
    ----------
    module : float
        mm.
    pressure_angle : float
        rad.
    dedendum, root_fillet, addendum : float
        Multiples of the module: root depth below the pitch line, rack tip round radius, tooth
        height above the pitch line (the flank is sampled to ``addendum + 0.02``).
    flank_points, round_points, flat_points : int
        Samples per element (flank samples keep the outline's chord error far below 1 um).
    """
    p = np.pi * module
    hf = dedendum * module
    rho = root_fillet * module
    # a rack point at height v maps to a gear point ~sqrt((r + v)^2 + (v cot(alpha))^2) from the axis,
    # beyond the tip r + addendum already for v = addendum; a small margin makes the clip robust
    v_top = (addendum + 0.02) * module
    sa, ca = np.sin(pressure_angle), np.cos(pressure_angle)
    nu_left = np.array([-ca, sa])  # left flank of the a-tooth: b material on the -u side
    # root round (centre in the cutter, tangent to v = -hf and to the left flank)
    cb = np.array([-p / 4 + ((-hf + rho) * sa - rho) / ca, -hf + rho])
    if cb[0] < -p / 2 or rho >= hf:
        raise ValueError("root fillet too large for the rack tooth")
    pts, nrm, elem = [], [], []
    u = np.linspace(-p / 2, cb[0], flat_points, endpoint=False)
    pts.append(np.stack([u, np.full_like(u, -hf)], -1))
    nrm.append(np.tile([0.0, 1.0], (len(u), 1)))
    elem.append(np.full(len(u), FLAT_ROOT_A))
    if rho > 0:
        ang = np.linspace(-np.pi / 2, -pressure_angle, round_points, endpoint=False)
        d = np.stack([np.cos(ang), np.sin(ang)], -1)
        pts.append(cb + rho * d)
        nrm.append(-d)
        elem.append(np.full(len(ang), ROUND_ROOT_A))
    lo = cb - rho * nu_left
    hi = np.array([-p / 4 + v_top * sa / ca, v_top])
    w = np.linspace(0.0, 1.0, flank_points)
    pts.append(lo + w[:, None] * (hi - lo))
    nrm.append(np.tile(nu_left, (len(w), 1)))
    elem.append(np.full(len(w), FLANK))
    left = np.concatenate(pts)
    left_n = np.concatenate(nrm)
    left_e = np.concatenate(elem)
    right = left[::-1] * [-1.0, 1.0]
    right_n = left_n[::-1] * [-1.0, 1.0]
    points = np.concatenate([left, right[:-1]])
    normals = np.concatenate([left_n, right_n[:-1]])
    element = np.concatenate([left_e, left_e[::-1][:-1]])
    flank_u = np.where(element == FLANK, np.where(points[:, 0] < 0, -p / 4, p / 4), np.nan)
    return RackProfile(points, normals, element, flank_u, p)


def offset_profile(points: np.ndarray, normals: np.ndarray, delta: float, gear: str) -> np.ndarray:
    """Move profile points by ``delta`` along the normal into gear ``gear``'s material (thinning it)."""
    sign = -1.0 if gear == "a" else 1.0
    return points + sign * delta * normals


def contact_abscissa(points: np.ndarray, normals: np.ndarray) -> np.ndarray:
    """Rack abscissa ``s`` of the pitch point when each profile point is in contact, mm."""
    s: np.ndarray = points[:, 0] - points[:, 1] * normals[:, 0] / normals[:, 1]
    return s


def envelope(points: np.ndarray, s: np.ndarray, frames: PitchFrames, gear: str) -> np.ndarray:
    """Map rack points in contact at pitch abscissa ``s`` into the gear frame, (n, 2) mm."""
    v = points[:, 1] if gear == "a" else -points[:, 1]
    mapped: np.ndarray = frames.point + (points[:, 0] - s)[:, None] * frames.tangent + v[:, None] * frames.normal
    return mapped


def osculating_frames(s: np.ndarray, centre_s: np.ndarray, centre: PitchFrames) -> PitchFrames:
    """Frames at ``s`` of the osculating circles of the pitch curve at ``centre_s`` (one per point).

    The involute-approximated method: the tooth around ``centre_s`` is the rack-cut tooth of that
    circle, which is an exact involute tooth of the circle, placed along the curve's normal.

    Parameters
    ----------
    s, centre_s : (n,) arrays
        Rack abscissae of the points and of their tooth centres, mm.
    centre : PitchFrames
        The pitch curve's frames at ``centre_s`` (n rows).
    """
    k = centre.curvature
    sigma = s - centre_s
    ks = k * sigma
    small = np.abs(ks) < 1e-6
    safe_k = np.where(small, 1.0, k)
    # sin(k s)/k and (1 - cos(k s))/k with their series where k s is tiny
    sin_k = np.where(small, sigma - k**2 * sigma**3 / 6, np.sin(ks) / safe_k)
    vers_k = np.where(small, k * sigma**2 / 2, (1 - np.cos(ks)) / safe_k)
    c, sn = np.cos(ks), np.sin(ks)
    point = centre.point + sin_k[:, None] * centre.tangent - vers_k[:, None] * centre.normal
    tangent = c[:, None] * centre.tangent - sn[:, None] * centre.normal
    normal = c[:, None] * centre.normal + sn[:, None] * centre.tangent
    return PitchFrames(point, tangent, normal, k)
