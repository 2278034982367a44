"""Mesh check: turn a gear pair through its working range and measure what the teeth do.

At every step the driving gear a is at ``x_a`` and the driven gear b at ``law(x_a)``, both placed in
the carrier frame (axis A at the origin, axis B at ``(a, 0)``). Three things are measured:

- interference area: 2D boolean intersection (shapely 2, vectorised over all steps) of the two
  outlines, clipped to a window around the pitch point first so each boolean is small;
- free play: how far gear b can turn either way about its axis, with gear a held, before a flank
  touches (``free_plus`` towards the flank gear a drives with, ``free_minus`` the other way). It is
  measured on the dense involute flanks: each pair of flanks enveloped by the same rack line is put
  in polar coordinates about axis B and the angular gap is taken at every radius both cover;
- transmission error: the driven angle at contact against the law, beyond the designed backlash.
  Backlash is a normal offset ``delta`` of both gears' flanks, so on each flank the pair is the
  zero-backlash conjugate pair with gear b's flank moved ``2 delta`` along the common normal; gear b
  closes that by turning ``2 delta / d_B``, where ``d_B`` is the distance from axis B to the line of
  action (through the pitch point, at the rack pressure angle to the pitch normal). For
  non-circular gears ``d_B`` differs between the two flanks and along the motion (``r_b cos(alpha
  +- mu)``), so the raw lag is not a constant; the transmission error is
  ``free_plus - 2 delta / d_B`` (driving flank) and likewise on the coast flank, and the report gives
  the largest magnitude of both. The raw lag (driven angle at contact minus the law) is kept too.

Backlash is the circumferential free play at the pitch curve, ``(free_plus + free_minus) r_b``.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np
import shapely

from fabricate.gears.pair import GearPair, MeshResult

if TYPE_CHECKING:
    from fabricate.mechanism import Law

#: Driving flank pairs whose gap is within this of the smallest count as touching together (rad).
CONTACT_TOLERANCE_RAD = 2e-6




def _pad_flanks(flanks: dict[int, np.ndarray]) -> tuple[np.ndarray, np.ndarray, int]:
    """Flanks as one NaN-padded array (rows by key - offset) and the key offset."""
    keys = np.array(sorted(flanks), dtype=np.int64)
    lo, hi = int(keys.min()), int(keys.max())
    width = max(len(v) for v in flanks.values())
    table = np.full((hi - lo + 1, width, 2), np.nan)
    present = np.zeros(hi - lo + 1, dtype=bool)
    for key, pts in flanks.items():
        table[key - lo, :len(pts)] = pts
        present[key - lo] = True
    return table, present, lo


def _polar_tables(table: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Per flank (row), radius-sorted polar coordinates about the gear's own axis, as one sorted
    search key (``radius + row * 1e6``) with the unwrapped angles, plus each row's radius range."""
    rho = np.hypot(table[..., 0], table[..., 1])
    phi = np.arctan2(table[..., 1], table[..., 0])
    order = np.argsort(np.where(np.isnan(rho), np.inf, rho), axis=1)
    rho = np.take_along_axis(rho, order, 1)
    phi = np.take_along_axis(phi, order, 1)
    filled = np.where(np.isnan(phi), 0.0, phi)
    phi = np.where(np.isnan(phi), np.nan, np.unwrap(filled, axis=1))
    rows = np.arange(len(table))[:, None] * 1e6
    key = np.where(np.isnan(rho), rows + 5e5, rho + rows)
    ranges = np.stack([np.nanmin(np.where(np.isnan(rho), np.inf, rho), 1),
                       np.nanmax(np.where(np.isnan(rho), -np.inf, rho), 1)], -1)
    return key.ravel(), phi.ravel(), ranges


#: Posed outline vertices (both gears) held at once by :func:`mesh_check` (measured 0.2 MB per step for 30-tooth
#: gears of ~14000 vertices, so ~50 MB of arrays and shapely geometry at the peak). 4000000 held ~1 GB: the
#: default finger's mesh check then peaked at 225 MB at 360 poses and 1318 MB at 5000 (5.9x); at 200000 it is
#: 1.16x (bench_bounds --poses-memory). Chunking changes no value: the areas are per step.
MESH_VERTICES_PER_CHUNK = 200_000

#: Posed flank points of gear a held at once by :func:`free_play` within :func:`mesh_check`: about 150 bytes
#: each across its temporaries (the finger's 720 steps in one piece peaked at 175 MB; 100000 points hold
#: ~15 MB). Chunking changes no value: every step is computed on its own.
MESH_FLANK_POINTS_PER_CHUNK = 100_000


def flank_reach(pair: GearPair) -> float:
    """Half-width of the window of rack flanks :func:`free_play` compares, mm along the pitch line.

    A flank pair touches, with the pitch point at rack abscissa ``s``, where the normal of its rack line
    through ``(s, 0)`` meets that line (the envelope condition, :mod:`fabricate.gears.rack`): at the height
    ``v = (s - u_j) sin(alpha) cos(alpha)`` off the pitch line, ``u_j`` being where the line crosses it.
    Teeth reach the addendum ``h_a`` off their pitch curves, so a touching pair has ``|u_j - s| <= h_a /
    (sin(alpha) cos(alpha))`` (the rack limit, e.g. 2.8 p at 10 deg and addendum 1.5 m; the tip circles of
    spur gears end the path of contact sooner). One pitch more holds the nearest driving pair where none
    touches (the next to enter or the last to leave, a pitch apart) and the small overshoots (the rack
    flank is sampled to ``h_a + 0.02 m``, the backlash offset). Never less than 1.6 p, the fixed window
    this replaces (too short for long paths of contact: 3.675 teeth measured against 4.14 for 100/100
    teeth at 10 deg with addendum 1.5 m).

    A closed gear has ``2 z`` flanks: a wider window would hold a flank of the smaller gear twice, its
    second rack line pairing it with a flank of the other gear far round (a spurious gap near -pi rad,
    e.g. 4/8 teeth at 14.5 deg), so there the window holds at most ``2 z`` flanks (for 3 teeth that
    is less than 1.6 p, which held some twice).

    Parameters
    ----------
    pair : GearPair
        Reads ``module``, ``closed``, ``teeth``, ``spec.addendum`` (× module) and
        ``spec.pressure_angle`` (rad).

    Returns
    -------
    float
        mm; :func:`free_play` takes the flanks crossing the pitch line within it either side.
    """
    p = np.pi * pair.module
    alpha = pair.spec.pressure_angle
    rack_limit = pair.spec.addendum * pair.module / (np.sin(alpha) * np.cos(alpha))
    reach = max(1.6 * p, rack_limit + p)
    if pair.closed:
        # free_play takes ceil(4 reach / p) + 1 flanks: 2 z at most (- 1.5, not - 1: rounding must not tip ceil)
        reach = min(reach, (2 * min(pair.teeth) - 1.5) * p / 4)
    return float(reach)


def free_play(pair: GearPair, x_a: np.ndarray, return_contacts: bool = False) -> tuple[np.ndarray, ...]:
    """Free rotation of gear b (rad) both ways at each ``x_a``; see the module docstring.

    Vectorised over steps: gear a's flanks within :func:`flank_reach` of the pitch point (along the
    pitch line) are mapped into gear b's frame and compared, at each of their points' radii about
    axis B, with the angle of gear b's flank of the same rack line (linear interpolation in a
    radius-sorted table).

    Parameters
    ----------
    pair : GearPair
        Needs ``pitch_model``, ``law``, ``module``, ``rack_origin``, ``closed``, ``teeth``,
        ``center_distance_mm``, ``cut_a.flanks``, ``cut_b.flanks`` and ``spec`` (addendum and
        pressure angle, for the window of flanks).
    x_a : (n,) array
        Driving angles relative to the carrier (rad).
    return_contacts : bool
        Also return the number of driving flank pairs in contact at each step.

    Returns
    -------
    free_plus, free_minus : (n,) arrays
        Free rotation of gear b towards / away from gear a's driving flanks (rad; negative where the
        flanks overlap, NaN where no flank pair of that side is in mesh).
    in_contact : (n,) int array
        Only with ``return_contacts``: driving flank pairs within :data:`CONTACT_TOLERANCE_RAD` of
        the closest one (their mean is the contact ratio); 0 where no driving pair is in mesh.
    """
    return _free_play(pair, x_a, _flank_tables(pair), return_contacts)


def _flank_tables(pair: GearPair) -> tuple[Any, ...]:
    """What :func:`free_play` compares, independent of the steps: both gears' padded flank tables and gear
    b's polar search table (made once per mesh check, not once per chunk of steps)."""
    table_a, present_a, off_a = _pad_flanks(pair.cut_a.flanks)
    table_b, present_b, off_b = _pad_flanks(pair.cut_b.flanks)
    key_b, phi_b, range_b = _polar_tables(table_b)
    return table_a, present_a, off_a, table_b, present_b, off_b, key_b, phi_b, range_b


def _flank_points_per_step(pair: GearPair) -> int:
    """Gear a's flank points :func:`free_play` poses at each step: the flanks in its window times the longest."""
    p = np.pi * pair.module
    count = int(np.ceil(2 * flank_reach(pair) / (p / 2))) + 1
    return count * max((len(v) for v in pair.cut_a.flanks.values()), default=1)


def _free_play(pair: GearPair, x_a: np.ndarray, tables: tuple[np.ndarray, ...], return_contacts: bool
               ) -> tuple[np.ndarray, ...]:
    """:func:`free_play` with its flank tables made (:func:`_flank_tables`).

    Every value is per point, so only the flank pairs in mesh are posed and only their points within gear b's
    flank's radii are looked up (compressed arrays, ~1/3 of the window's points for the finger): the others
    would only be set to inf. The same operations on the same values: the same bits as the full arrays.
    """
    pitch = pair.pitch_model
    p = np.pi * pair.module
    s = pitch.s_of_x(x_a)
    theta_b = np.asarray(pair.law(x_a), dtype=np.float64)
    table_a, present_a, off_a, table_b, present_b, off_b, key_b, phi_b, range_b = tables
    reach = flank_reach(pair)
    j_lo = np.ceil((s - reach - pair.rack_origin + p / 4) / (p / 2)).astype(np.int64)
    count = int(np.ceil(2 * reach / (p / 2))) + 1  # the flanks from s - reach to s + reach
    j = j_lo[:, None] + np.arange(count)[None, :]  # (n, J) rack flank indices
    if pair.closed:
        ra, rb = j % (2 * pair.teeth[0]) - off_a, j % (2 * pair.teeth[1]) - off_b
    else:
        ra, rb = j - off_a, j - off_b
    ok = (ra >= 0) & (ra < len(table_a)) & (rb >= 0) & (rb < len(table_b))
    ra, rb = np.where(ok, ra, 0), np.where(ok, rb, 0)
    ok &= present_a[ra] & present_b[rb]
    pairs = np.flatnonzero(ok)  # (F,) flank pairs in mesh, into the (n, J) window
    step, row = pairs // count, rb.ravel()[pairs]
    pts = table_a[ra.ravel()[pairs]]  # (F, K, 2) in gear a's frame
    # gear-a frame -> carrier -> gear-b frame: q = R(-theta_b) (R(x_a) g - (a, 0))
    ang = x_a - theta_b
    c, sn = np.cos(ang)[step, None], np.sin(ang)[step, None]
    cb, sb = np.cos(theta_b)[step, None], np.sin(theta_b)[step, None]
    a = pair.center_distance_mm
    qx = c * pts[..., 0] - sn * pts[..., 1] - a * cb
    qy = sn * pts[..., 0] + c * pts[..., 1] + a * sb
    rho = np.hypot(qx, qy)
    inside = (rho >= range_b[row][:, 0:1]) & (rho <= range_b[row][:, 1:2]) & np.isfinite(rho)
    at = np.flatnonzero(inside)  # (P,) points within their gear-b flank's radii, into (F, K)
    flank = at // pts.shape[1]
    key = rho.ravel()[at] + row[flank] * 1e6
    idx = np.clip(np.searchsorted(key_b, key), 1, len(key_b) - 1)
    # a point exactly at a row's lowest radius lands on that row's first key, whose left neighbour is the
    # previous row: interpolate from that key to the next instead (w = 0 gives its angle)
    idx = np.where((key_b[idx] == key) & (idx < len(key_b) - 1), idx + 1, idx)
    k0, k1 = key_b[idx - 1], key_b[idx]
    w = np.clip((key - k0) / np.where(k1 > k0, k1 - k0, 1.0), 0.0, 1.0)
    phi_on_b = phi_b[idx - 1] + w * (phi_b[idx] - phi_b[idx - 1])
    # the interpolation must stay within row rb (the keys of one row are rb*1e6 + radius)
    keep = (np.floor(k0 / 1e6) == row[flank]) & (np.floor(k1 / 1e6) == row[flank]) & np.isfinite(phi_on_b)
    at, flank, phi_on_b = at[keep], flank[keep], phi_on_b[keep]
    gap = (np.arctan2(qy.ravel()[at], qx.ravel()[at]) - phi_on_b + np.pi) % (2 * np.pi) - np.pi
    # even flanks: left flank of an a tooth, gear-b material on the -u side; turning b positively
    # moves its material towards +u, closing these gaps (odd flanks: the reverse)
    even = (j % 2 == 0)
    gap = np.where(even.ravel()[pairs][flank], gap, -gap)
    # each flank pair's least gap (its points are contiguous in ``at``); inf where none is inside
    per_flank = np.full(ok.shape, np.inf)
    if len(gap):
        starts = np.flatnonzero(np.r_[True, flank[1:] != flank[:-1]])
        per_flank.ravel()[pairs[flank[starts]]] = np.minimum.reduceat(gap, starts)
    plus = np.where(even, per_flank, np.inf).min(axis=1)
    minus = np.where(~even, per_flank, np.inf).min(axis=1)
    # driving flank pairs touching together (within CONTACT_TOLERANCE_RAD of the closest): the teeth in contact.
    # Only pairs that share a radius count: with none in mesh plus is inf and inf <= inf would count them all
    in_contact = np.count_nonzero(even & np.isfinite(per_flank) & (per_flank <= plus[:, None] + CONTACT_TOLERANCE_RAD),
                                  axis=1)
    plus[~np.isfinite(plus)] = np.nan
    minus[~np.isfinite(minus)] = np.nan
    if return_contacts:
        return plus, minus, in_contact
    return plus, minus


def _rotate_all(angles: np.ndarray, points: np.ndarray) -> np.ndarray:
    """``points`` (m, 2) turned by each of ``angles`` (n,): (n, m, 2)."""
    c, sn = np.cos(angles)[:, None], np.sin(angles)[:, None]
    return np.stack([c * points[:, 0] - sn * points[:, 1], sn * points[:, 0] + c * points[:, 1]], -1)


def interference_areas(pair: GearPair, x_a: np.ndarray) -> np.ndarray:
    """Overlap area (mm^2) of the two outlines at each ``x_a`` (vectorised shapely booleans)."""
    theta_b = np.asarray(pair.law(x_a), dtype=np.float64)
    a = pair.center_distance_mm
    out_a = np.asarray(pair.outline_a)
    out_b = np.asarray(pair.outline_b)
    r_a = pair.pitch_model.radii(x_a, "a")[0]
    # shift each step so its pitch point is at the origin: one fixed clip window for all steps
    shift = np.stack([r_a, np.zeros_like(r_a)], -1)[:, None, :]
    world_a = _rotate_all(x_a, out_a) - shift
    world_b = _rotate_all(theta_b, out_b) + np.array([a, 0.0]) - shift
    ring_a = np.concatenate([world_a, world_a[:, :1]], axis=1)
    ring_b = np.concatenate([world_b, world_b[:, :1]], axis=1)
    polys_a = shapely.polygons(ring_a)
    polys_b = shapely.polygons(ring_b)
    m = pair.module
    half = 3.5 * np.pi * m
    win_a = shapely.clip_by_rect(polys_a, -3.0 * m, -half, 3.0 * m, half)
    win_b = shapely.clip_by_rect(polys_b, -3.0 * m, -half, 3.0 * m, half)
    # the overlay only where the windows meet: disjoint ones overlap by 0.0 (an empty intersection's area), and
    # the predicate costs ~1/8 of the overlay (a sound pair meets at no step: 720 intersections were 0.038 s)
    area = np.zeros(len(x_a), dtype=np.float64)
    meet = np.flatnonzero(shapely.intersects(win_a, win_b))
    if len(meet):
        area[meet] = shapely.area(shapely.intersection(win_a[meet], win_b[meet]))
    return area


def mesh_check(pair: GearPair, x_a_values: np.ndarray | None = None, steps: int | None = None) -> MeshResult:
    """Turn ``pair`` through its working range (or through ``x_a_values``, rad) and measure.

    Parameters
    ----------
    pair : GearPair
    x_a_values : (n,) array, optional
        Driving angles relative to the carrier (e.g. the assembly's actual angles).
    steps : int, optional
        Number of evenly spaced steps over the working range (default: the spec's ``mesh_steps``); for
        closed pairs over as many turns of gear a as gear b needs to turn once.
    """
    if x_a_values is None:
        n = int(steps or pair.spec.mesh_steps)
        lo, hi = pair.working_range
        if pair.closed:
            # until gear b has turned once too (z_b / z_a turns of a when b has more teeth)
            hi = lo + 2 * np.pi * max(1.0, pair.teeth[1] / pair.teeth[0])
        x_a_values = np.linspace(lo, hi, n, endpoint=not pair.closed)
    x = np.asarray(x_a_values, dtype=np.float64)
    # both measures hold every step's posed outlines at once: run them on chunks of steps so that
    # memory stays bounded whatever mesh_steps and the tooth count are (the values are per step)
    vertices = len(pair.outline_a) + len(pair.outline_b)
    chunk = max(1, MESH_VERTICES_PER_CHUNK // max(1, vertices))
    flank_chunk = max(1, MESH_FLANK_POINTS_PER_CHUNK // max(1, _flank_points_per_step(pair)))
    tables = _flank_tables(pair) if len(x) else ()
    parts = [_free_play(pair, x[i:i + flank_chunk], tables, True) for i in range(0, len(x), flank_chunk)]
    plus, minus, contacts = (np.concatenate([part[k] for part in parts]) if parts else np.zeros(0)
                             for k in range(3))
    r_b = pair.pitch_model.radii(x, "b")[0]
    lag_plus, lag_minus = designed_lag(pair, x)
    err_plus, err_minus = plus - lag_plus, minus - lag_minus
    te = np.where(np.abs(err_plus) >= np.abs(err_minus), err_plus, err_minus)
    area = (np.concatenate([interference_areas(pair, x[i:i + chunk]) for i in range(0, len(x), chunk)])
            if len(x) else np.zeros(0))
    return MeshResult(x_a=x, free_plus=plus, free_minus=minus, backlash_mm=(plus + minus) * r_b,
                      transmission_error=te, contact_lag=plus, interference_area_mm2=area,
                      teeth_in_contact=contacts)


def designed_lag(pair: GearPair, x_a: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Free rotation of gear b the designed backlash alone allows on each flank (rad): ``2 delta /
    d_B`` with ``d_B`` the distance from axis B to that flank's line of action (module docstring)."""
    alpha = pair.spec.pressure_angle
    delta = pair.spec.backlash_mm * np.cos(alpha) / 4.0
    frames = pair.pitch_model.frames_at_x(x_a, "a")
    c, s = np.cos(x_a), np.sin(x_a)
    # world y-components of the pitch tangent and outward normal of gear a at the pitch point
    t_y = s * frames.tangent[:, 0] + c * frames.tangent[:, 1]
    n_y = s * frames.normal[:, 0] + c * frames.normal[:, 1]
    r_b = pair.pitch_model.radii(x_a, "b")[0]
    # lines of action through the pitch point (r_a, 0); their distance from B = (a, 0) is r_b |nu_y|
    arm_left = r_b * np.abs(-np.cos(alpha) * t_y + np.sin(alpha) * n_y)
    arm_right = r_b * np.abs(np.cos(alpha) * t_y + np.sin(alpha) * n_y)
    return 2 * delta / arm_left, 2 * delta / arm_right


def _window_chains(outline: np.ndarray, centre_angles: np.ndarray, half_angle: float) -> np.ndarray:
    """Per step, the contiguous run of outline vertices whose polar angle lies within
    ``half_angle`` of ``centre_angles[k]``, padded to one length, closed through the axis: (n, K, 2)."""
    phi = np.arctan2(outline[:, 1], outline[:, 0])
    chains = []
    for centre in centre_angles:
        inside = np.abs((phi - centre + np.pi) % (2 * np.pi) - np.pi) <= half_angle
        idx = np.flatnonzero(inside)
        if len(idx) == 0:
            chains.append(np.zeros((1, 2)))
            continue
        # a run that wraps past the ring's end starts after the largest gap in the indices
        gaps = np.diff(idx)
        if len(idx) > 1 and gaps.max() > 1:
            cut = int(np.argmax(gaps)) + 1
            idx = np.concatenate([idx[cut:], idx[:cut]])
        run = np.arange(idx[0], idx[0] + ((idx[-1] - idx[0]) % len(outline)) + 1) % len(outline)
        chains.append(np.vstack([outline[run], [[0.0, 0.0]]]))
    width = max(len(c) for c in chains)
    return np.stack([np.vstack([c, np.repeat(c[-1:], width - len(c), 0)]) for c in chains])


def free_play_outlines(outline_a: np.ndarray, outline_b: np.ndarray, law: Law, center_distance: float,
                       x_a: np.ndarray, module: float, max_angle: float = 0.02,
                       tolerance: float = 1e-9) -> tuple[np.ndarray, np.ndarray]:
    """Free rotation of gear b both ways (rad) from outlines alone, by bisection on 2D booleans.

    Independent of how the outlines were made (used to measure other generators' gears the same
    way as ours, e.g. in ``tests/benchmarks/bench_gears.py``). Each gear is reduced to a pie-shaped
    window around the mesh (a contiguous run of its outline closed through its axis); gear b is
    turned about its axis until the windows touch. NaN where the pair already overlaps at the law.
    """
    from fabricate.gears.law import law_derivative

    x_a = np.asarray(x_a, dtype=np.float64)
    theta_b = np.asarray(law(x_a), dtype=np.float64)
    ratio = -law_derivative(law, x_a, 1)
    r_a = center_distance * ratio / (1 + ratio)
    half_a = 3.0 * np.pi * module / r_a.min()
    half_b = 3.0 * np.pi * module / (center_distance - r_a).max()
    win_a = _window_chains(outline_a, -x_a, half_a)
    win_b = _window_chains(outline_b, np.pi - theta_b, half_b)
    world_a = np.stack([np.cos(x_a)[:, None] * win_a[..., 0] - np.sin(x_a)[:, None] * win_a[..., 1],
                        np.sin(x_a)[:, None] * win_a[..., 0] + np.cos(x_a)[:, None] * win_a[..., 1]], -1)
    polys_a = shapely.polygons(np.concatenate([world_a, world_a[:, :1]], 1))
    shapely.prepare(polys_a)

    def touching(extra: np.ndarray) -> np.ndarray:
        ang = (theta_b + extra)[:, None]
        wx = np.cos(ang) * win_b[..., 0] - np.sin(ang) * win_b[..., 1] + center_distance
        wy = np.sin(ang) * win_b[..., 0] + np.cos(ang) * win_b[..., 1]
        ring = np.stack([wx, wy], -1)
        polys_b = shapely.polygons(np.concatenate([ring, ring[:, :1]], 1))
        # a positive overlap area, not just touching: exact contact of polylines is measure zero
        return np.asarray(shapely.area(shapely.intersection(polys_a, polys_b)) > 1e-12)

    overlap = touching(np.zeros_like(x_a))
    result = []
    for sign in (1.0, -1.0):
        lo, hi = np.zeros_like(x_a), np.full_like(x_a, max_angle)
        while np.max(hi - lo) > tolerance:
            mid = 0.5 * (lo + hi)
            hit = touching(sign * mid)
            hi = np.where(hit, mid, hi)
            lo = np.where(hit, lo, mid)
        result.append(np.where(overlap, np.nan, 0.5 * (lo + hi)))
    return result[0], result[1]
