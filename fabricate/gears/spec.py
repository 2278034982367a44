"""The generic ``[gears]`` template table: how gear teeth are cut and checked.

Every template may carry a ``[gears]`` table; when it is absent the defaults below apply. The table
describes the *teeth* (module, pressure angle, proportions, method) and the *checks*; the ratio law
and the centre distance come from the mechanism (a :class:`~fabricate.mechanism.GearCoupling`).

Keys (all optional)
-------------------
``module_mm``            float in [0.05, 50], or ``"auto"`` (the default when absent). Module m in mm. A number
                         fixes it: a process that cannot make its teeth fails the build naming the tooth feature
                         (tip land, undercut, Lewis/Hertz safety). ``"auto"``: the smallest standard module
                         (DIN 780-1 series 1 and 2) whose teeth the process makes and the load allows
                         (:mod:`fabricate.gears.auto`); a closed pair given ``teeth`` takes the module its tooth
                         count and centre distance give instead.
``pressure_angle_deg``   float in [10, 35], or ``"auto"``; default 20, or ``"auto"`` when the module is chosen
                         (``module_mm`` auto and no ``teeth``). ``"auto"``: the first of the standard full-depth
                         systems 20, 22.5, 25 degrees (:data:`STANDARD_PRESSURE_ANGLES_DEG`) at which a standard
                         module passes (:mod:`fabricate.gears.auto`). Pressure angle of the generating rack. Above about
                         22 degrees the default root fillet no longer fits the rack's tooth space and
                         is reduced to the largest that does (above about 31 degrees also the default
                         dedendum); a ``root_fillet`` or ``dedendum`` given explicitly that does not fit
                         is an error naming its limit.
``addendum``             float in [0.3, 1.5] × m, default 1.0.
``dedendum``             float in [0.5, 2.0] × m, default 1.25; must exceed ``addendum`` (tip clearance).
``root_fillet``          float in [0, 0.5] × m, default 0.38. Rack tip round radius (cuts the fillet).
``backlash_mm``          float in [0, 1], default 0.05. Circumferential backlash j of the pair at the
                         pitch curve; each gear's teeth are thinned by j/2, every flank moved into its
                         tooth by the true normal offset j cos(alpha) / 4.
``method``               ``"exact"`` (default: both gears cut by one virtual rack rolling on the pitch
                         curves) or ``"approx"`` (each tooth an involute tooth of the local osculating
                         circle).
``compare_methods``      bool, default true. Also build the other method and report the largest deviation
                         between the two outlines in µm.
``spare_teeth``          int in [1, 20], default 1. Extra engagements beyond each end of a sector's range.
``mesh_steps``           int in [720, 7200], default 720. Poses of the mesh check over the working range
                         (time grows with steps × outline vertices; the bound keeps the check within
                         the resource budget of :mod:`fabricate.bounds`). Also steps × (z_a + z_b) <=
                         300000, checked when the tooth counts are known (an error names the largest
                         number of steps).
``closed``               bool. Absent: as the design kind says (sector for a finger, closed for a gear pair).
``teeth``                [z_a, z_b], integers in [3, 100]. Tooth counts of a closed pair (with the centre distance
                         they fix the module, unless ``module_mm`` is given, which then fixes the
                         centre distance).
``min_teeth``            int in [3, 100], default 8. Fewest teeth a closed gear may have (a check).
``bore_mm``              float in (0, 50]. Bore of each gear on its axis. Absent: the process pin diameter.
``hub_diameter_mm``      float > 0. Hub around the bore. Absent: the parts layer decides.

Example
-------
.. code-block:: toml

    [gears]
    module_mm = 1.0
    method = "exact"
    backlash_mm = 0.08
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from fabricate.bounds import MAX_MESH_STEPS, MAX_TEETH
from fabricate.errors import SpecError
from fabricate.gears.rack import MIN_ROOT_LAND, rack_fit
from fabricate.table import Table

METHODS = ("exact", "approx")
#: Smallest module: finer teeth than no process resolves (SLA min feature 0.3 mm) only cost time.
MIN_MODULE_MM = 0.05
#: Pressure angles an automatic one is chosen from, preferred first: the full-depth spur-gear systems of Shigley's
#: *Mechanical Engineering Design* (Budynas & Nisbett, 9th ed.) Table 13-1 (20, 22.5, 25 deg, addendum 1 m,
#: dedendum 1.25 m); 20 deg is ISO 53:1998's basic rack, 25 deg AGMA 201.02's other full-depth system.
STANDARD_PRESSURE_ANGLES_DEG = (20.0, 22.5, 25.0)


@dataclass(frozen=True)
class GearSpec:
    """Validated ``[gears]`` table. Lengths in mm; ``addendum``, ``dedendum``, ``root_fillet`` × module.

    Attributes
    ----------
    module_mm : float or None
        Module in mm; None means ``"auto"`` (see the module docstring; a closed pair with ``teeth`` takes the
        module they give).
    pressure_angle_deg : float
        Rack pressure angle, degrees.
    addendum, dedendum, root_fillet : float
        Tooth proportions as multiples of the module.
    backlash_mm : float
        Circumferential backlash of the pair at the pitch curve, mm.
    method : str
        ``"exact"`` or ``"approx"``.
    compare_methods : bool
        Build the other method too and report the deviation.
    spare_teeth : int
        Extra engagements at each end of a sector.
    mesh_steps : int
        Poses in the mesh check.
    closed : bool or None
        Closed gears, sectors, or None for the kind's default.
    teeth : tuple of int or None
        (z_a, z_b) for a closed pair.
    min_teeth : int
        Smallest acceptable tooth count of a closed gear.
    bore_mm, hub_diameter_mm : float or None
        Bore and hub diameters; None lets the pipeline use the process pin / parts defaults.
    """

    module_mm: float | None = None
    pressure_angle_deg: float = 20.0
    addendum: float = 1.0
    dedendum: float = 1.25
    root_fillet: float = 0.38
    backlash_mm: float = 0.05
    method: str = "exact"
    compare_methods: bool = True
    spare_teeth: int = 1
    mesh_steps: int = 720
    closed: bool | None = None
    teeth: tuple[int, int] | None = None
    min_teeth: int = 8
    bore_mm: float | None = None
    hub_diameter_mm: float | None = None
    #: ``pressure_angle_deg = "auto"``: the candidates (angle deg, dedendum, root fillet), each with the rack
    #: proportions that fit at it, preferred first; () when the angle is fixed
    pressure_angle_candidates: tuple[tuple[float, float, float], ...] = ()

    @property
    def pressure_angle(self) -> float:
        """Pressure angle in radians."""
        return math.radians(self.pressure_angle_deg)

    def module_or(self, default_mm: float) -> float:
        """The module, or ``default_mm`` when the template leaves it to the method."""
        return self.module_mm if self.module_mm is not None else float(default_mm)


def parse_gear_spec(table: Table, retarget: bool = False) -> GearSpec:
    """Read the ``[gears]`` table (an empty table gives the defaults).

    Parameters
    ----------
    table : Table
        The ``[gears]`` table, ``{}`` when absent.
    retarget : bool
        The design is built for another process than its template's (``--process``): a ``module_mm`` and a
        ``pressure_angle_deg`` the template fixes for its own process are chosen again (``"auto"``), except a
        module that, with ``teeth``, fixes the geometry of a closed pair.

    Returns
    -------
    GearSpec

    Raises
    ------
    SpecError
        On a field out of range, naming ``gears.<key>`` and the accepted range.
    """
    # "auto" and an absent key are the same request: the module is chosen (fabricate.gears.auto)
    auto = table.has("module_mm") and table.raw("module_mm") == "auto"
    if table.has("module_mm") and isinstance(table.raw("module_mm"), str) and not auto:
        raise SpecError(table.field("module_mm"), f'expected a module in mm or "auto", got "{table.raw("module_mm")}"')
    module = None if auto else table.number("module_mm", None, min=MIN_MODULE_MM, max=50.0)
    if retarget and auto is False and table.has("module_mm") and not table.has("teeth"):
        module = None  # --process: a module that only sizes the teeth is chosen again for the new process
    angle_auto = table.has("pressure_angle_deg") and table.raw("pressure_angle_deg") == "auto"
    if table.has("pressure_angle_deg") and isinstance(table.raw("pressure_angle_deg"), str) and not angle_auto:
        raise SpecError(table.field("pressure_angle_deg"),
                        f'expected an angle in degrees or "auto", got "{table.raw("pressure_angle_deg")}"')
    pressure = 20.0 if angle_auto else table.number("pressure_angle_deg", 20.0, min=10.0, max=35.0)
    addendum = table.number("addendum", 1.0, min=0.3, max=1.5)
    dedendum = table.number("dedendum", 1.25, min=0.5, max=2.0)
    fillet = table.number("root_fillet", 0.38, min=0.0, max=0.5)
    backlash = table.number("backlash_mm", 0.05, min=0.0, max=1.0)
    method = table.string("method", "exact", choices=METHODS)
    compare = table.boolean("compare_methods", True)
    spare = table.integer("spare_teeth", 1, min=1, max=20)
    steps = table.integer("mesh_steps", 720, min=720, max=MAX_MESH_STEPS)
    closed = table.boolean("closed") if table.has("closed") else None
    teeth_arr = table.array("teeth", None, shape=(2,), min=3, max=MAX_TEETH)
    teeth: tuple[int, int] | None = None
    if teeth_arr is not None:
        for i, z in enumerate(teeth_arr):
            if z != round(z):
                raise SpecError(f"{table.field('teeth')}[{i}]", f"expected a whole number, got {z:g}")
        teeth = (int(teeth_arr[0]), int(teeth_arr[1]))
    min_teeth = table.integer("min_teeth", 8, min=3, max=MAX_TEETH)
    bore = table.number("bore_mm", None, positive=True, max=50.0)
    hub = table.number("hub_diameter_mm", None, positive=True, max=1000.0)
    table.finish()
    if dedendum <= addendum:
        raise SpecError(table.field("dedendum"),
                        f"dedendum {dedendum:g} m must exceed addendum {addendum:g} m (tip clearance); "
                        f"use dedendum >= {addendum + 0.25:g}")
    chosen = module is None and teeth is None
    if angle_auto and not chosen:
        raise SpecError(table.field("pressure_angle_deg"), '"auto" is chosen together with the module: set '
                                                           'module_mm = "auto" (without teeth) or give an angle')
    candidates: tuple[tuple[float, float, float], ...] = ()
    if chosen and (angle_auto or not table.has("pressure_angle_deg") or retarget):
        candidates = _angle_candidates(table, addendum, dedendum, fillet)
        pressure = candidates[0][0]
    dedendum, fillet = _fit_rack(table, pressure, addendum, dedendum, fillet)
    if hub is not None and bore is not None and hub <= bore:
        raise SpecError(table.field("hub_diameter_mm"),
                        f"hub {hub:g} mm must be larger than the bore {bore:g} mm")
    if teeth is not None and min(teeth) < min_teeth:
        raise SpecError(table.field("teeth"),
                        f"{min(teeth)} teeth is below min_teeth = {min_teeth}; "
                        "use more teeth (a smaller module)")
    return GearSpec(module_mm=module, pressure_angle_deg=pressure, addendum=addendum, dedendum=dedendum,
                    root_fillet=fillet, backlash_mm=backlash, method=method, compare_methods=compare,
                    spare_teeth=spare, mesh_steps=steps, closed=closed, teeth=teeth, min_teeth=min_teeth,
                    bore_mm=bore, hub_diameter_mm=hub, pressure_angle_candidates=candidates)


def _angle_candidates(table: Table, addendum: float, dedendum: float,
                      fillet: float) -> tuple[tuple[float, float, float], ...]:
    """The standard pressure angles an automatic one is chosen from, each with the dedendum and root fillet cut
    at it (:func:`_fit_rack`); an angle at which a dedendum or fillet the template gives does not fit is left out
    (20 deg, the first, must fit: its error is the template's)."""
    out = []
    for k, angle in enumerate(STANDARD_PRESSURE_ANGLES_DEG):
        try:
            out.append((angle, *_fit_rack(table, angle, addendum, dedendum, fillet)))
        except SpecError:
            if k == 0:
                raise
    return tuple(out)


def _fit_rack(table: Table, pressure_deg: float, addendum: float, dedendum: float,
              fillet: float) -> tuple[float, float]:
    """The dedendum and root fillet actually cut: the template's, or the largest that fit the rack.

    A steep pressure angle narrows the rack's tooth space at the root (see
    :func:`fabricate.gears.rack.rack_fit`). Defaults adapt to it so that every pressure angle of the
    documented range builds; values the template gives explicitly are kept or refused with their limit.
    """
    max_dedendum, _ = rack_fit(math.radians(pressure_deg), dedendum)
    if dedendum > max_dedendum:
        if table.has("dedendum"):
            raise SpecError(table.field("dedendum"),
                            f"dedendum {dedendum:g} m does not fit the rack's tooth space at pressure angle "
                            f"{pressure_deg:g} deg; at most {_floor3(max_dedendum):g} m")
        if max_dedendum <= addendum:
            # the other gear's tip would reach this gear's root: no tip clearance is left
            limit = math.degrees(math.atan((math.pi / 4 - MIN_ROOT_LAND) / addendum))
            raise SpecError(table.field("pressure_angle_deg"),
                            f"at {pressure_deg:g} deg the rack's tooth space is {max_dedendum:.3g} m deep, not "
                            f"deeper than the addendum {addendum:g} m; at most {math.floor(limit * 10) / 10:g} deg "
                            "with this addendum (or a smaller addendum)")
        dedendum = max_dedendum
    _, max_fillet = rack_fit(math.radians(pressure_deg), dedendum)
    if fillet > max_fillet:
        if table.has("root_fillet"):
            raise SpecError(table.field("root_fillet"),
                            f"root fillet {fillet:g} m does not fit the rack's tooth space at pressure angle "
                            f"{pressure_deg:g} deg with dedendum {dedendum:g} m; at most {_floor3(max_fillet):g} m")
        fillet = max_fillet
    return dedendum, fillet


def _floor3(value: float) -> float:
    return math.floor(value * 1000.0) / 1000.0
