"""The mount of a rotary actuator: a plate on its flange (part role ``"mount"``), its screws, and the
standoffs that stand it on the ground part (on the ground's mounting holes that keep clear of the actuator and
of what moves, else on new holes in the ground's free material, else on arms the ground part grows); and the
turn of the actuator's body that lets the standoffs clear it. A mixin of
:class:`fabricate.drive.rotary.RotaryPlacement`, which sets the attributes declared here."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np
import shapely
import shapely.ops

from fabricate.catalogue.hardware import ISO4762, screw
from fabricate.drive import geometry as geo
from fabricate.drive.records import MOUNT_PART, Fastener, Standoff, fit_hole, screw_size
from fabricate.errors import GeometryError, SpecError
from fabricate.parts.model import BulgePath, Hole, Part
from fabricate.parts.profiles import circle_hull
from fabricate.planar import rotation

if TYPE_CHECKING:
    from fabricate.catalogue.actuators import Actuator
    from fabricate.mechanism import Mechanism, Motion
    from fabricate.parts.partset import PartSet
    from fabricate.process import ProcessSpec


@dataclass
class _Plate:
    """The mount plate as its steps add to it: its holes, the circles its outline covers, the screws (BOM
    rows) and the solids of its screw heads and bought standoff tubes."""

    holes: list[Hole] = field(default_factory=list)
    circles: list[tuple[np.ndarray, float]] = field(default_factory=list)
    fasteners: list[Fastener] = field(default_factory=list)
    solids: list[geo.Solid] = field(default_factory=list)


def _off(region: Any, pts: np.ndarray) -> np.ndarray:
    """Which of ``pts`` (m, 2) are at a distance over 0 from ``region``: ``shapely.distance(region, points) > 0``,
    the exact distance taken only for the points a prepared ``dwithin`` finds within 1e-6 mm (~40x faster on
    the finger's 10000 grid points; the others are over 0 whatever rounding the distance has)."""
    points = shapely.points(pts)
    if region.is_empty:  # distance is NaN: no point is off it (dwithin would keep every one)
        return np.asarray(shapely.distance(region, points) > 0.0)
    shapely.prepare(region)  # a spatial index on the geometry itself: its values do not change
    near = np.asarray(shapely.dwithin(region, points, 1e-6), dtype=bool)
    off: np.ndarray = ~near
    off[near] = shapely.distance(region, points[near]) > 0.0
    return off


class MountPlacement:
    """The mount plate and standoffs of a rotary actuator (a mixin: see the module docstring)."""

    design: Any
    mechanism: Mechanism
    motion: Motion
    ps: PartSet
    entry: Actuator
    process: ProcessSpec
    tol: float
    ground: str
    joint: str
    c: float
    comp: float
    wall: float
    notes: list[str]
    new_ground_holes: list[Hole]
    resized_ground_holes: list[Hole]  # the ground's mounting holes opened for a larger standoff screw
    ground_arms: list[np.ndarray]

    def _output_reach(self) -> float:
        raise NotImplementedError  # RotaryPlacement's

    def _plate_mm(self) -> float:
        """The mount plate's thickness: the process's stock, but on a cut process the thickest stock the shop
        lists (``stock_thickness_mm``), no thicker than the process's, whose shop rules the plate's fixed features
        meet. The actuator fixes where its screw holes sit against the body's cutout: a standard servo's tab holes
        leave 2.3 mm of acrylic to its case, and the same holes' pilots are below the minimum hole of a 6 mm sheet
        (half its thickness), where a 3 mm sheet takes both. With none that does, the process's stock (the shop
        check names what fails)."""
        t0 = float(self.process.thickness_mm)
        if self.process.technique != "cut" or not self.entry.mounting_holes:
            return t0
        stock = {float(s) for s in getattr(self.process, "stock_thickness_mm", ()) or () if float(s) < t0 - 1e-9}
        return next((t for t in sorted(stock | {t0}, reverse=True) if self._plate_meets_shop(t)), t0)

    def _plate_meets_shop(self, t: float) -> bool:
        """Whether a mount plate ``t`` thick meets the shop's rules for that stock
        (:class:`fabricate.checks.shop.ShopRules`) where the actuator fixes its features: its fixing holes and
        the standoffs' pilots not below the minimum hole, the web between the fixing holes and between each and
        the body's cutouts (in the actuator's frame, where the placement does not matter)."""
        from fabricate.checks.shop import ShopRules

        entry = self.entry
        rules = ShopRules.of(self.process, t)
        pz = geo.mount_plate_z(entry)
        holes = [(np.array([mh.x, mh.y]), 0.5 * geo.fastening(entry, mh, t, self.c, self.comp).plate_hole_mm)
                 for mh in entry.mounting_holes or ()]
        d = float(screw_size(float(self.design.parts.mounting_hole_mm)).lstrip("M"))
        diameters = [2.0 * r for _, r in holes] + [geo.PILOT_FRACTION * d + self.comp]
        if min(diameters) < rules.min_hole_mm - 1e-9:
            return False
        cuts = [shapely.Polygon(r) for r in geo.plate_cutouts(entry, pz, pz + t, self.c)]
        for i, (a, ra) in enumerate(holes):
            if any(float(np.hypot(*(a - b))) - ra - rb < rules.min_web_mm - 1e-9 for b, rb in holes[i + 1:]):
                return False
            if any(cut.distance(shapely.Point(*a)) - ra < rules.min_web_mm - 1e-9 for cut in cuts):
                return False
        return True

    def _orient(self, angle: float, centre: np.ndarray, ground: Part, flip: bool, z_face: float) -> float:
        """The turn nearest ``angle`` (10 degree steps) at which the actuator's body keeps clear of the
        standoffs on the ground's mounting holes (between its mount plate and the ground part) and of the
        pins, washers and tubes fixed to the ground (or swept by a moving one) at the body's heights."""
        entry = self.entry
        if not entry.body:
            return angle
        t = self._plate_mm()
        pz = geo.mount_plate_z(entry)
        place0 = geo.Placement(centre, angle, flip, z_face)
        plate = place0.z_range(pz, pz + t)
        g0, g1 = float(ground.z_mm), float(ground.z_mm + ground.thickness_mm)
        lo, hi = (g1, plate[0]) if flip else (plate[1], g0)
        obstacles: list[tuple[Any, float, float]] = [
            (shapely.Point(*h.centre).buffer(0.5 * h.diameter_mm + max(self.wall, 0.25 * h.diameter_mm), 32), lo, hi)
            for h in ground.holes if h.joint.startswith("mount_")]
        standoffs = [geom for geom, _, _ in obstacles]
        obstacles += self._pin_obstacles()
        if not obstacles:
            return angle
        screws = []  # the plate's own screws, their holes and heads: the standoffs must stand clear of them
        for mh in entry.mounting_holes or ():
            f = geo.fastening(entry, mh, t, self.c, self.comp)
            head = ISO4762[f.size].head_d_mm if f.tapped else 0.0
            screws.append((np.array([mh.x, mh.y]), max(0.5 * f.plate_hole_mm + self.wall, 0.5 * head)))
        for k in sorted(range(-18, 19), key=lambda k: (abs(k), k)):
            turn = angle + math.radians(10.0 * k)
            place = geo.Placement(centre, turn, flip, z_face)
            clear = not any(geom.distance(shapely.Point(*place.plan(xy))) < r for xy, r in screws for geom in standoffs)
            for b in entry.body:
                z0, z1 = place.z_range(b.z0, b.z1)
                ring = geo.rectangle(b.x0 - self.c, b.y0 - self.c, b.x1 + self.c, b.y1 + self.c)
                shape = shapely.Polygon(geo.placed_ring(ring, place))
                if not clear or any(o0 < z1 - 1e-9 and o1 > z0 + 1e-9 and shape.intersects(geom)
                                    for geom, o0, o1 in obstacles):
                    clear = False
                    break
            if clear:
                return turn
        return angle

    def _pin_obstacles(self) -> list[tuple[Any, float, float]]:
        """Pins, washers and tubes as (plan region in the ground's frame, z0, z1): discs for those the ground
        holds, the path swept for the others."""
        out: list[tuple[Any, float, float]] = []
        pick = np.unique(np.linspace(0, len(self.motion.inputs) - 1, min(90, len(self.motion.inputs)))
                         .round().astype(int))
        base = self.motion.pose(self.ground)[pick]

        def region(body: str, centre: np.ndarray, r: float) -> Any:
            if body == self.ground:
                return shapely.Point(*centre).buffer(r, 32)
            poses = self.motion.pose(body)[pick]
            world = np.einsum("nij,j->ni", rotation(poses[:, 2]), centre) + poses[:, :2]
            local = np.einsum("nji,nj->ni", rotation(base[:, 2]), world - base[:, :2])
            return shapely.LineString(local).buffer(r, 16) if len(local) > 1 else shapely.Point(*local[0]).buffer(r)

        for sp in self.ps.spacers:
            if self.joint in sp.joint.split("+"):
                continue  # the driver pin's: they go with it
            out.append((region(sp.body, np.asarray(sp.centre, dtype=float), 0.5 * float(sp.outer_diameter_mm)),
                        float(sp.z_mm), float(sp.z_mm + sp.length_mm)))
        holes = {(p.body, h.joint): h.centre for p in self.ps.parts for h in p.holes}
        for pin in self.ps.pins:
            if self.joint in pin.joint.split("+"):
                continue
            centre = holes.get((pin.bodies[0], pin.joint))
            if centre is not None:
                out.append((region(pin.bodies[0], np.asarray(centre, dtype=float), 0.5 * float(pin.diameter_mm)),
                            float(pin.z_mm), float(pin.z_mm + pin.length_mm)))
        return out

    def _standoff_sites(self, place: geo.Placement, ground: Part, lo: float, hi: float,
                        screw_mm: float | None = None) -> list[Hole]:
        """Where the standoffs stand on the ground part (holes of the ground): its mounting holes that keep
        clear of the actuator (body, output) and of every part moving between the plate and the ground; else
        two new holes (``standoff_1``, ``standoff_2``), as far apart as the ground part's free material allows;
        none if it has none. ``screw_mm``: the standoffs' screw (default the design's mounting screw; a larger
        one cannot use the ground's mounting holes, sized for that)."""
        from fabricate.parts.partset import swept_region

        entry, c = self.entry, self.c
        design_mm = float(self.design.parts.mounting_hole_mm)
        screw_mm = design_mm if screw_mm is None else float(screw_mm)
        nominal = screw_mm + 2.0 * c
        hole_d = nominal + self.comp
        outer = hole_d + 2.0 * max(self.wall, 0.25 * hole_d)
        forbidden = []
        for b in entry.body or ():
            z0, z1 = place.z_range(b.z0, b.z1)
            if z0 < hi - 1e-9 and z1 > lo + 1e-9:
                forbidden.append(shapely.Polygon(geo.placed_ring(geo.rectangle(b.x0, b.y0, b.x1, b.y1), place)))
        out_reach = self._output_reach()
        forbidden.append(shapely.Point(*place.centre).buffer(out_reach, 64))
        t = self._plate_mm()
        for mh in entry.mounting_holes or ():  # the plate's own screws: their holes and heads
            f = geo.fastening(entry, mh, t, c, self.comp)
            head = ISO4762[f.size].head_d_mm if f.tapped else 0.0
            radius = max(0.5 * f.plate_hole_mm + self.wall, 0.5 * head)
            forbidden.append(shapely.Point(*place.plan(np.array([mh.x, mh.y]))).buffer(radius, 32))
        if self.ground == self.mechanism.ground:
            moving = {p.body: p.outline for p in self.ps.parts if p.body != self.ground
                      and p.z_mm < hi - 1e-9 and p.z_mm + p.thickness_mm > lo + 1e-9}
            if moving:
                forbidden.append(swept_region(moving, self.motion))
            forbidden += self._pin_hardware(lo, hi)
        keep_out = shapely.union_all(forbidden).buffer(0.5 * outer + c)
        existing = [h for h in ground.holes if h.joint.startswith("mount_")]
        clear = [h for h in existing if not keep_out.contains(shapely.Point(h.centre))
                 and keep_out.distance(shapely.Point(h.centre)) > 0.0]
        if len(clear) >= min(2, len(existing)) and clear:
            if screw_mm > design_mm + 1e-9:  # a larger screw than the holes were cut for: open them to its clearance
                clear = [fit_hole(h.joint, h.centre, nominal, self.comp, fit="clearance") for h in clear]
                self.resized_ground_holes = list(clear)
            return clear
        # new sites on the ground part's own material, clear of its holes
        inset = max(0.5 * outer, 0.5 * hole_d + self.wall)
        region = shapely.Polygon(ground.outline.polygon(0.05)).buffer(-inset)
        for h in ground.holes:
            region = region.difference(shapely.Point(h.centre).buffer(0.5 * (h.diameter_mm + hole_d) + self.wall))
        region = region.difference(keep_out)
        if region.is_empty or region.area < 1e-6:
            return self._standoff_arms(place, ground, keep_out, nominal, hole_d, outer) or clear
        xs, ys = np.meshgrid(*(np.arange(a, b + 0.25, 0.25) for a, b in
                               zip(region.bounds[:2], region.bounds[2:], strict=True)))
        pts = np.column_stack([xs.ravel(), ys.ravel()])
        pts = pts[shapely.contains_xy(region, pts[:, 0], pts[:, 1])]
        if len(pts) == 0:
            pts = np.array(region.representative_point().coords)
        if len(pts) == 1:
            picks = pts
        else:
            gaps = np.hypot(*(pts[:, None, :] - pts[None, :, :]).transpose(2, 0, 1)) if len(pts) < 1500 else None
            if gaps is None:  # a coarse pair: the points farthest along the region's long direction
                u = pts - pts.mean(axis=0)
                axis = np.linalg.svd(u, full_matrices=False)[2][0]
                picks = pts[[int(np.argmin(u @ axis)), int(np.argmax(u @ axis))]]
            else:
                i, j = np.unravel_index(int(np.argmax(gaps)), gaps.shape)
                picks = pts[[i, j]] if gaps[i, j] >= outer + self.wall else pts[[i]]
        self.new_ground_holes = [fit_hole(f"actuator_standoff_{k + 1}", p, nominal, self.comp, fit="clearance")
                                 for k, p in enumerate(picks)]
        return list(self.new_ground_holes)

    def _pin_hardware(self, lo: float, hi: float) -> list[Any]:
        """Plan regions (ground frame) the pins' washers and tubes between ``lo`` and ``hi`` take: a disc on a
        ground pin, the path a moving one sweeps (a washer may be wider than the boss it sits on)."""
        out = []
        pick = np.unique(np.linspace(0, len(self.motion.inputs) - 1, min(90, len(self.motion.inputs)))
                         .round().astype(int))
        for sp in self.ps.spacers:
            if self.joint in sp.joint.split("+") or not (sp.z_mm < hi - 1e-9 and sp.z_mm + sp.length_mm > lo + 1e-9):
                continue
            r = 0.5 * float(sp.outer_diameter_mm)
            centre = np.asarray(sp.centre, dtype=float)
            if sp.body == self.ground:
                out.append(shapely.Point(*centre).buffer(r, 32))
                continue
            poses = self.motion.pose(sp.body)[pick]
            path = np.einsum("nij,j->ni", rotation(poses[:, 2]), centre) + poses[:, :2]
            out.append(shapely.LineString(path).buffer(r, 16) if len(path) > 1 else shapely.Point(*path[0]).buffer(r))
        return out

    def _standoff_arms(self, place: geo.Placement, ground: Part, keep_out: Any, nominal: float, hole_d: float,
                       outer: float) -> list[Hole]:
        """Two standoff sites off the ground part, each on an arm the ground part grows to reach it (in its own
        layer, clear of what moves there): the sites nearest the ground part that clear ``keep_out``, at least
        three standoffs apart. Sets :attr:`ground_arms`; [] when no site is found."""
        from fabricate.parts.partset import swept_region

        if self.ground != self.mechanism.ground:
            return []
        body = shapely.Polygon(ground.outline.polygon(0.05))
        g0, g1 = ground.z_mm, ground.z_mm + ground.thickness_mm
        same_layer = {p.body: p.outline for p in self.ps.parts if p.body != self.ground
                      and p.z_mm < g1 - 1e-9 and p.z_mm + p.thickness_mm > g0 + 1e-9}
        swept = swept_region(same_layer, self.motion).buffer(self.c + 0.5) if same_layer else shapely.Polygon()
        boss = max(0.5 * outer, 0.5 * hole_d + self.wall)
        reach = max([math.hypot(x, y) for b in self.entry.body or () for x in (b.x0, b.x1) for y in (b.y0, b.y1)],
                    default=20.0) + 4.0 * outer
        xs, ys = np.meshgrid(*(np.arange(-reach, reach + 1.0, 1.0),) * 2)
        pts = np.column_stack([xs.ravel(), ys.ravel()]) + np.asarray(place.centre, dtype=float)
        # clear of the ground's own holes by a wall (a new hole beside an old one)
        taken = shapely.union_all([shapely.Point(*h.centre).buffer(0.5 * (h.diameter_mm + hole_d) + self.wall, 32)
                                   for h in ground.holes]) if ground.holes else shapely.Polygon()
        blocked = shapely.union_all([keep_out, taken])
        pts = pts[~shapely.contains_xy(blocked, pts[:, 0], pts[:, 1])]
        pts = pts[_off(blocked, pts)]
        order = np.argsort(shapely.distance(body, shapely.points(pts)))
        sites: list[np.ndarray] = []
        arms: list[np.ndarray] = []
        for k in order:
            p = pts[k]
            if any(float(np.hypot(*(p - q))) < 3.0 * outer for q in sites):
                continue
            near = np.array(shapely.ops.nearest_points(body, shapely.Point(p))[0].coords[0])
            arm = circle_hull(np.array([near, p]), np.array([boss, boss])) if np.hypot(*(p - near)) > 1e-6 \
                else circle_hull(p[None, :], boss)
            ring = arm.polygon(self.tol)  # the wall round the new hole is measured on these chords
            if not swept.is_empty and shapely.Polygon(ring).intersects(swept):
                continue
            sites.append(p)
            arms.append(ring)
            if len(sites) == 2:
                break
        if len(sites) < 2:
            return []
        self.ground_arms = arms
        self.new_ground_holes = [fit_hole(f"actuator_standoff_{k + 1}", p, nominal, self.comp, fit="clearance")
                                 for k, p in enumerate(sites)]
        return list(self.new_ground_holes)

    def _standoff_size(self, clamp_mm: float, plate_mm: float) -> str:
        """The standoffs' screw size: the design's mounting screw (``parts.mounting_hole_mm``), else, where no
        standard length of it passes ``clamp_mm`` (the ground part and the standoffs) and engages the plate,
        the next larger ISO 4762 size that does: ISO 4762 stops M3 at 30 mm and M4 at 40, and an actuator over
        a tall stack of sheets stands higher than that. The design's size when none does (the build then names
        the stack)."""
        size = screw_size(float(self.design.parts.mounting_hole_mm))
        larger = sorted((s for s in ISO4762 if float(s.lstrip("M")) >= float(size.lstrip("M"))),
                        key=lambda s: float(s.lstrip("M")))
        for candidate in larger:
            try:
                geo.screw_into(candidate, clamp_mm, plate_mm)
            except SpecError:
                continue
            return candidate
        return size

    def _mount(self, place: geo.Placement, ground: Part, flip: bool
               ) -> tuple[Part, list[Fastener], list[Standoff], list[Part], list[geo.Solid]]:
        """The mount plate on the actuator's flange, its screws, and the standoffs to the ground part."""
        from fabricate.parts.partset import SlottedPart

        entry, process = self.entry, self.process
        t = self._plate_mm()
        pz = geo.mount_plate_z(entry)
        z0, z1 = place.z_range(pz, pz + t)
        plate = _Plate()
        self._plate_screws(plate, place, pz, t)
        slots = [BulgePath.polyline(geo.placed_ring(r, place)) for r in geo.plate_cutouts(entry, pz, pz + t, self.c)]
        for cut in slots:
            plate.circles += [(v, self.wall) for v in cut.vertices]
        plate.circles.append((np.asarray(place.centre, dtype=float), self.wall))
        g0, g1 = float(ground.z_mm), float(ground.z_mm + ground.thickness_mm)
        standoffs, standoff_parts = self._standoffs(plate, place, ground, (g1, z0) if flip else (z1, g0), t)
        circles = plate.circles
        outline = circle_hull(np.array([c for c, _ in circles]), np.array([r for _, r in circles]))
        layers = [p.layer for p in self.ps.parts]
        part = SlottedPart(name=MOUNT_PART, body=self.ground, outline=outline, holes=tuple(plate.holes),
                           thickness_mm=t, z_mm=z0, layer=max(layers) + 1 if flip else min(layers) - 1,
                           process=process.name, role="mount", slots=tuple(slots))
        return part, plate.fasteners, standoffs, standoff_parts, plate.solids

    def _plate_screws(self, plate: _Plate, place: geo.Placement, pz: float, t: float) -> None:
        """The screws from the actuator's flange into the plate (``t`` thick from ``pz``): their holes, the
        plate round them, their BOM rows (one per kind) and the heads of those into the actuator's own
        tapped holes."""
        entry, tol = self.entry, self.tol
        by_screw: dict[tuple[str, float, float, str], int] = {}
        for k, mh in enumerate(entry.mounting_holes or ()):
            f = geo.fastening(entry, mh, t, self.c, self.comp)
            centre = place.plan(np.array([mh.x, mh.y]))
            nominal = f.plate_hole_mm - self.comp
            plate.holes.append(fit_hole(f"actuator_screw_{k + 1}", centre, nominal, self.comp,
                                        fit="clearance" if f.tapped else "tapped"))
            plate.circles.append((centre, 0.5 * f.plate_hole_mm + self.wall))
            s = screw(f.size, f.clamp_mm, f.engagement_mm)
            key = (s.designation, s.clamp_mm, s.engagement_mm,
                   "actuator to its mount plate" + (" (into its tapped holes)" if f.tapped
                                                     else " (taps into the plate)"))
            by_screw[key] = by_screw.get(key, 0) + 1
            if f.tapped:  # the head bears on the plate's far face from the actuator
                plate.solids.append(geo.Solid(f"actuator_screw_head_{k + 1}", "fixing",
                                              (geo.circle_ring(centre, s.head_d_mm, tol),),
                                              *place.z_range(pz + t, pz + t + s.head_h_mm)))
        plate.fasteners += [Fastener(d, n, purpose, clamp, engage)
                            for (d, clamp, engage, purpose), n in by_screw.items()]

    def _standoffs(self, plate: _Plate, place: geo.Placement, ground: Part, span: tuple[float, float],
                   t: float) -> tuple[list[Standoff], list[Part]]:
        """The standoffs between the ground part and the plate (``span``: their z from, to): printed parts
        for an additive process, else bought tubes (solids); the plate's pilot holes and the screws through
        them. None (a note) where the ground has no place for them."""
        from fabricate.parts.partset import safe_name

        process, tol = self.process, self.tol
        lo, hi = span
        standoffs: list[Standoff] = []
        standoff_parts: list[Part] = []
        size = self._standoff_size(float(ground.thickness_mm) + (hi - lo), t)
        d = float(size.lstrip("M"))
        mounting = self._standoff_sites(place, ground, lo, hi, d) if hi - lo > 1e-6 else []
        if not mounting:
            self.notes.append("no place on the ground part for the mount's standoffs: fix the mount plate to the "
                              "same base as the ground part")
            return standoffs, standoff_parts
        printed = process.technique == "additive"
        for h in mounting:
            inner = float(h.diameter_mm)
            outer = inner + 2.0 * max(self.wall, 0.25 * inner)
            st = Standoff(h.joint, np.asarray(h.centre, dtype=float), inner, outer, hi - lo, lo, printed)
            standoffs.append(st)
            pilot = geo.PILOT_FRACTION * d
            name = h.joint.removeprefix("actuator_")
            plate.holes.append(fit_hole(f"actuator_{name}", st.centre, pilot, self.comp, fit="tapped"))
            plate.circles.append((st.centre, max(0.5 * outer, 0.5 * (pilot + self.comp) + self.wall)))
            ring = circle_hull(st.centre[None, :], 0.5 * outer)
            if printed:
                standoff_parts.append(Part(name=safe_name(name if name.startswith("standoff") else
                                                          f"standoff_{name}"), body=self.ground, outline=ring,
                                           holes=(fit_hole(h.joint, st.centre, inner - self.comp, self.comp),),
                                           thickness_mm=st.length_mm, z_mm=st.z_mm, layer=ground.layer,
                                           process=process.name, role="standoff"))
            else:
                plate.solids.append(geo.Solid(name if name.startswith("standoff") else f"standoff_{name}",
                                              "standoff", (geo.circle_ring(st.centre, outer, tol),
                                                           geo.circle_ring(st.centre, inner, tol)[::-1]),
                                              st.z_mm, st.z_mm + st.length_mm))
        try:
            fix = geo.screw_into(size, float(ground.thickness_mm) + (hi - lo), t)
        except SpecError as exc:
            # a stack too tall for a standard screw through its standoffs: the design, not the input, is at
            # fault (a build failure naming it, exit 1)
            raise GeometryError(f"the actuator's mount plate stands {hi - lo:.3g} mm off the ground part: "
                                f"no standard screw clamps it through its standoffs ({exc.message})") from None
        plate.fasteners.append(Fastener(fix.designation, len(mounting), "mount plate to the ground part through "
                                        "the standoffs (taps into the plate)", fix.clamp_mm, fix.engagement_mm))
        return standoffs, standoff_parts
