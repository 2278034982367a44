"""Real, common actuators: the body a part must clear, the mount, the output interface and the rating.

Frame of every entry: the output axis is the z axis, +z pointing out of the actuator (for a linear
actuator: the direction the rod extends), the origin on that axis at the face the output leaves from
(a servo's top face, a motor's mounting face; a linear actuator's rod-end hole, retracted). Boxes are
axis-aligned ``(x0, y0, z0, x1, y1, z1)`` in mm.

Every number carries its source (the comment beside it, and :attr:`Actuator.sources` per field). A
value no public source gave is ``None`` and its field is named in :attr:`Actuator.gaps` with the
reason; :attr:`Actuator.complete` says whether an entry has what a build needs (a body, a mount, an
output interface and a torque or force rating). Nothing is filled in from memory.

Torques are N·mm, forces N, speeds degrees/s (rotary) or mm/s (linear), voltages V.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

from fabricate.catalogue._units import GF_CM_NMM, KGF_CM_NMM, KGF_MM_NMM, rpm_to_deg_s, s_per_60deg_to_deg_s
from fabricate.errors import SpecError

KINDS = ("servo", "gearmotor", "stepper", "tendon", "linear")


@dataclass(frozen=True)
class Box:
    """An axis-aligned box (mm)."""

    x0: float
    y0: float
    z0: float
    x1: float
    y1: float
    z1: float


@dataclass(frozen=True)
class Hole:
    """A mounting hole through a flange (or a tapped hole), centre ``(x, y)`` on the face at ``z``."""

    x: float
    y: float
    z: float
    diameter_mm: float
    thread: str | None = None


@dataclass(frozen=True)
class Spline:
    """A servo output spline (``teeth`` None where no source gives the count)."""

    teeth: int | None
    diameter_mm: float
    length_mm: float


@dataclass(frozen=True)
class Horn:
    """The horn supplied with a servo: the hub that sits on the spline and the holes in its arms (in the
    horn's own frame: hub axis = z, arm holes at ``(x, y)``)."""

    name: str
    hub_d_mm: float
    hub_height_mm: float
    arm_thickness_mm: float
    center_screw_hole_mm: float
    socket_d_mm: float
    socket_depth_mm: float
    arm_holes: tuple[Hole, ...]


@dataclass(frozen=True)
class Shaft:
    """A round output shaft with ``flats`` flats (0 round, 1 D, 2 double-D); ``across_flats_mm`` is the
    distance from a flat to the far side (D) or between the flats (double-D)."""

    diameter_mm: float
    length_mm: float
    flats: int | None
    across_flats_mm: float | None
    flat_length_mm: float | None


@dataclass(frozen=True)
class Actuator:
    """One catalogue actuator (see the module docstring for frame and units)."""

    key: str
    name: str
    kind: str
    body: tuple[Box, ...] | None
    mounting_holes: tuple[Hole, ...] | None
    spline: Spline | None
    horn: Horn | None
    shaft: Shaft | None
    rated_torque_nmm: float | None
    stall_torque_nmm: float | None
    rated_force_n: float | None
    stall_force_n: float | None
    no_load_speed: float | None
    voltage_v: float | None
    stroke_mm: float | None
    closed_length_mm: float | None
    sources: tuple[tuple[str, str], ...]
    gaps: tuple[tuple[str, str], ...] = ()

    def __post_init__(self) -> None:
        if self.kind not in KINDS:
            raise SpecError("kind", f"expected one of {list(KINDS)}, got {self.kind!r}")

    def source(self, field: str) -> str:
        """Where the value(s) of ``field`` come from."""
        return dict(self.sources)[field]

    def gap(self, field: str) -> str | None:
        """Why ``field`` is missing, or None if it is not."""
        return dict(self.gaps).get(field)

    @property
    def speed_unit(self) -> str:
        return "mm/s" if self.kind == "linear" else "deg/s"

    @property
    def envelope(self) -> Box | None:
        """The bounding box of :attr:`body` (None without a body)."""
        if not self.body:
            return None
        return Box(min(b.x0 for b in self.body), min(b.y0 for b in self.body), min(b.z0 for b in self.body),
                   max(b.x1 for b in self.body), max(b.y1 for b in self.body), max(b.z1 for b in self.body))

    @property
    def complete(self) -> bool:
        """True if the entry has all a build needs: a body and a mount (or, off-board, neither), an
        output interface and a rating."""
        if self.kind == "tendon":
            return self.rated_force_n is not None or self.stall_force_n is not None
        interface = self.spline is not None or self.shaft is not None or self.kind == "linear"
        rating = any(v is not None for v in (self.rated_torque_nmm, self.stall_torque_nmm,
                                             self.rated_force_n, self.stall_force_n))
        return bool(self.body) and bool(self.mounting_holes) and interface and rating


# ---------------------------------------------------------------------------------------------------------
# Hobby servos (SG90, MG90S)
# ---------------------------------------------------------------------------------------------------------

KARTCHNB_SERVOS = ("B. Kartchner, openscad-servo-library, servos/{file} ('Actual measurements from clones that I "
                   "have'; https://github.com/kartchnb/openscad-servo-library)")
KARTCHNB_HORN = ("B. Kartchner, servohorn_lib, servohorns/20t.scad (global parameters) and servohorns/20t/i.scad "
                 "(type I arms), measured 20T horns (https://github.com/kartchnb/servohorn_lib)")
SG90_DATASHEET = ("TowerPro SG90 datasheet figures as listed on the NUS wiki page 'SG90 Micro Servo' "
                  "(https://nus.atlassian.net/wiki/pages/diffpages.action?originalId=27625571&pageId=27625578): "
                  "stall torque 1.8 kgf·cm, operating speed 0.1 s/60 degree, operating voltage 4.8 V")
MG90S_DATASHEET = ("MG90S datasheet (TowerPro layout), https://raw.githubusercontent.com/TrDA-hab/Projects/master/"
                   "Servo%2BESP8266/MG90S-Datasheet.pdf: stall torque 1.8 kgf·cm (4.8 V), 2.2 kgf·cm (6 V); "
                   "operating speed 0.1 s/60 degree (4.8 V), 0.08 s/60 degree (6 V); 4.8-6.0 V")


def _servo_body(aft: float, wing: float, fore: float, body_w: float, wing_w: float, axle_off: float,
                body_l: float) -> tuple[Box, ...]:
    """A hobby servo's case and mounting tabs from Kartchner's measurement set (his diagram: ``aft``
    below the tabs, ``wing`` the tab thickness, ``fore`` above them to the top face; ``body_w`` along the
    case, ``wing_w`` over the tabs, ``axle_off`` from the case centre to the axle; ``body_l`` across)."""
    cx = -axle_off                               # the axle at x = 0, the case centre behind it
    top_of_tab = -fore
    return (Box(cx - body_w / 2, -body_l / 2, -(aft + wing + fore), cx + body_w / 2, body_l / 2, 0.0),
            Box(cx - wing_w / 2, -body_l / 2, top_of_tab - wing, cx + wing_w / 2, body_l / 2, top_of_tab))


def _servo_holes(axle_off: float, fore: float, hole_x: float, hole_d: float,
                 hole_y: float = 0.0) -> tuple[Hole, ...]:
    """The tab holes, ``hole_x`` either side of the case centre, on the tabs' top face: one per tab on the
    centre line, or (``hole_y`` > 0) a pair per tab at ``±hole_y`` across it."""
    ys = (0.0,) if hole_y == 0.0 else (-hole_y, hole_y)
    return tuple(Hole(-axle_off + sx * hole_x, y, -fore, hole_d) for sx in (-1.0, 1.0) for y in ys)


HORN_20T_I = Horn(
    name="20T type I (double arm)",
    hub_d_mm=6.92,  # 20t.scad "center diameter" 6.92
    hub_height_mm=3.73,  # 20t.scad "cap height" 3.73 (arm and centre cap)
    arm_thickness_mm=1.43,  # 20t.scad "thickness" 1.43
    center_screw_hole_mm=2.50,  # 20t.scad "screw hole diameter" 2.50
    socket_d_mm=4.60,  # 20t.scad "socket diameter" 4.60
    socket_depth_mm=2.00,  # 20t.scad "socket depth" 2.00
    # 20t/i.scad: arms at 0° and 180°, holes Ø1.50 at offsets 5, 7, 9, 11, 13, 15 mm
    arm_holes=tuple(Hole(sign * off, 0.0, 0.0, 1.50) for sign in (1.0, -1.0)  # 20t/i.scad hole Ø1.50
                    for off in (5.0, 7.0, 9.0, 11.0, 13.0, 15.0)),  # 20t/i.scad offsets 5..15
)

# SG90 (clone) as measured (sg90_clone.scad): aft 15.56, wing 2.46, fore 8.34, axle 3.08, body width
# 22.62, wing width 32.38, axle offset 6.19, axle Ø4.00, body length 12.38, spline 20T, holes ±13.97 Ø2.60
_SG90 = {"aft": 15.56, "wing": 2.46, "fore": 8.34, "body_w": 22.62, "wing_w": 32.38,  # sg90_clone.scad
         "axle_off": 6.19, "body_l": 12.38}  # sg90_clone.scad
SG90 = Actuator(
    key="sg90", name="TowerPro SG90 micro servo", kind="servo",
    body=_servo_body(**_SG90),
    mounting_holes=_servo_holes(6.19, 8.34, 13.97, 2.60),  # sg90_clone.scad holes x ±13.97, Ø2.60
    spline=Spline(teeth=20, diameter_mm=4.00, length_mm=3.08),  # sg90_clone.scad "20T", axle Ø4.00, axle h 3.08
    horn=HORN_20T_I, shaft=None,
    rated_torque_nmm=None,
    stall_torque_nmm=1.8 * KGF_CM_NMM,  # SG90 datasheet: stall torque 1.8 kgf·cm (4.8 V)
    rated_force_n=None, stall_force_n=None,
    no_load_speed=s_per_60deg_to_deg_s(0.1),  # SG90 datasheet: 0.1 s/60 degree
    voltage_v=4.8,  # SG90 datasheet: operating voltage 4.8 V
    stroke_mm=None, closed_length_mm=None,
    sources=(("body", KARTCHNB_SERVOS.format(file="sg90_clone.scad")),
             ("mounting_holes", KARTCHNB_SERVOS.format(file="sg90_clone.scad")),
             ("spline", KARTCHNB_SERVOS.format(file="sg90_clone.scad")),
             ("horn", KARTCHNB_HORN),
             ("stall_torque_nmm", SG90_DATASHEET), ("no_load_speed", SG90_DATASHEET),
             ("voltage_v", SG90_DATASHEET)),
    gaps=(("rated_torque_nmm", "the SG90 datasheet figures give the stall torque only (1.8 kgf·cm at 4.8 V); no "
                               "continuous or rated torque"),),
)

# MG90S (clone) as measured (mg90s_clone.scad): aft 18.31, wing 2.53, fore 7.62, axle 4.00, body width
# 22.92, wing width 32.38, axle offset 6.19, axle Ø4.70, body length 12.38, spline 20T, holes ±14.16 Ø2.20
_MG90S = {"aft": 18.31, "wing": 2.53, "fore": 7.62, "body_w": 22.92, "wing_w": 32.38,  # mg90s_clone.scad
          "axle_off": 6.19, "body_l": 12.38}  # mg90s_clone.scad
MG90S = Actuator(
    key="mg90s", name="TowerPro MG90S metal-gear micro servo", kind="servo",
    body=_servo_body(**_MG90S),
    mounting_holes=_servo_holes(6.19, 7.62, 14.16, 2.20),  # mg90s_clone.scad holes x ±14.16, Ø2.20
    spline=Spline(teeth=20, diameter_mm=4.70, length_mm=4.00),  # mg90s_clone.scad "20T", axle Ø4.70, axle h 4.00
    horn=HORN_20T_I, shaft=None,
    rated_torque_nmm=None,
    stall_torque_nmm=1.8 * KGF_CM_NMM,  # MG90S datasheet: stall torque 1.8 kgf·cm (4.8 V)
    rated_force_n=None, stall_force_n=None,
    no_load_speed=s_per_60deg_to_deg_s(0.1),  # MG90S datasheet: 0.1 s/60 degree (4.8 V)
    voltage_v=4.8,  # MG90S datasheet: 4.8 V (the lower end of 4.8-6.0 V, where the ratings above hold)
    stroke_mm=None, closed_length_mm=None,
    sources=(("body", KARTCHNB_SERVOS.format(file="mg90s_clone.scad")),
             ("mounting_holes", KARTCHNB_SERVOS.format(file="mg90s_clone.scad")),
             ("spline", KARTCHNB_SERVOS.format(file="mg90s_clone.scad")),
             ("horn", KARTCHNB_HORN + " (the 20T size the MG90S spline measures)"),
             ("stall_torque_nmm", MG90S_DATASHEET), ("no_load_speed", MG90S_DATASHEET),
             ("voltage_v", MG90S_DATASHEET)),
    gaps=(("rated_torque_nmm", "the MG90S datasheet gives the stall torque only (1.8 kgf·cm at 4.8 V, 2.2 at "
                               "6 V); no continuous or rated torque"),),
)

# ---------------------------------------------------------------------------------------------------------
# Standard-size servo (MG996R class)
# ---------------------------------------------------------------------------------------------------------

MG996R_DATASHEET = ("TowerPro MG996R datasheet, Handsontec EMH-1056 (https://www.handsontec.com/dataspecs/motor_fan/"
                    "MG996R.pdf), read through a public transcription of its spec lines and page-2 drawing: 'Stall "
                    "torque: 9.4 kgf·cm (4.8 V), 11 kgf·cm (6 V); Operating speed: 0.17 s/60º (4.8 V), 0.14 s/60º "
                    "(6 V); Operating voltage: 4.8 V a 7.2 V'; drawing: case 40.3 long, 53.6 over the tabs, 20 wide, "
                    "36.6 high, 26.6 from the base to the tabs, 47.6 high with the horn")
#: The MG996R drawing's own envelope (mm), kept to check the body below against it (not used to build it).
MG996R_DRAWING = {"case_l": 40.3, "over_tabs": 53.6, "case_w": 20.0,  # MG996R_DATASHEET drawing
                  "case_h": 36.6, "base_to_tabs": 26.6}  # MG996R_DATASHEET drawing

# The drawing does not place the output axis in the case nor dimension the tab holes, so the body and mount
# are Kartchner's measured standard-size servo (s3003_clone.scad): aft 26.79, wing 4.00, fore 6.43, axle
# 5.52, body width 40.86, wing width 54.15, axle offset 10.15, axle Ø5.80, body length 20.30, four holes at
# x ±24.43, y ±4.50, Ø4.42. Every one of its outer dimensions is at or up to 0.62 mm over the MG996R
# drawing's (40.86 ≥ 40.3, 54.15 ≥ 53.6, 20.30 ≥ 20, 37.22 ≥ 36.6, 26.79 ≥ 26.6), so the interference proof
# sees a body no smaller than the MG996R (tests/catalogue/test_actuators.py checks it).
_STD = {"aft": 26.79, "wing": 4.00, "fore": 6.43, "body_w": 40.86, "wing_w": 54.15,  # s3003_clone.scad
        "axle_off": 10.15, "body_l": 20.30}  # s3003_clone.scad
# The MG996R's tooth count: no maker's text states it. One public model of the MG996R does:
# NoahMSchool/RobotArmEPQ EPQCAD/Component_data.scad (the version with per-servo spline fields) gives
# "MG996R_data = [... 25, //TeethCount  6.4, //shaft_diameter  4, //shaft_depth]". It agrees with the
# 25-tooth "Futaba 3F Standard Spline" of hugokernel/OpenSCAD_ServoArms servo_arm.scad (FUTABA_3F_SPLINE:
# 25 teeth, Ø5.92 head), within 0.12 mm of the Ø5.80 axle Kartchner measured (s3003_clone.scad). The same
# Component_data.scad also says 25 for the SG90, which Kartchner measured as 20T: its counts are a
# modeller's, so the count is entered "as modelled".
MG996R_TEETH = ("NoahMSchool/RobotArmEPQ, EPQCAD/Component_data.scad (https://github.com/NoahMSchool/RobotArmEPQ), "
                "MG996R_data: '25, //TeethCount' (as modelled; the same file gives 25 for its SG90, which "
                "Kartchner measured 20T, so this is a modeller's count, not a maker's); consistent with "
                "hugokernel/OpenSCAD_ServoArms servo_arm.scad (https://github.com/hugokernel/OpenSCAD_ServoArms) "
                "FUTABA_3F_SPLINE 'Futaba 3F Standard Spline': 25 teeth, head Ø5.92")
MG996R = Actuator(
    key="mg996r", name="TowerPro MG996R metal-gear standard servo", kind="servo",
    body=_servo_body(**_STD),
    mounting_holes=_servo_holes(10.15, 6.43, 24.43, 4.42, 4.50),  # s3003_clone.scad x ±24.43, y ±4.50, Ø4.42
    spline=Spline(teeth=25,  # MG996R_TEETH: Component_data.scad MG996R_data '25, //TeethCount' (as modelled)
                  diameter_mm=5.80, length_mm=5.52),  # s3003_clone.scad axle Ø5.80, axle h 5.52
    horn=None, shaft=None,
    rated_torque_nmm=None,
    stall_torque_nmm=9.4 * KGF_CM_NMM,  # MG996R_DATASHEET: stall torque 9.4 kgf·cm (4.8 V)
    rated_force_n=None, stall_force_n=None,
    no_load_speed=s_per_60deg_to_deg_s(0.17),  # MG996R_DATASHEET: 0.17 s/60º (4.8 V)
    voltage_v=4.8,  # MG996R_DATASHEET: 4.8 V, the lower end of 4.8-7.2 V, where the figures above hold
    stroke_mm=None, closed_length_mm=None,
    sources=(("body", KARTCHNB_SERVOS.format(file="s3003_clone.scad") + "; cross-checked against the "
              + MG996R_DATASHEET),
             ("mounting_holes", KARTCHNB_SERVOS.format(file="s3003_clone.scad") + " (the standard-size servo's "
              "four tab holes; the MG996R ships with 4 fixing screws, " + MG996R_DATASHEET + ")"),
             ("spline", KARTCHNB_SERVOS.format(file="s3003_clone.scad") + " (axle diameter and height); "
              "teeth: " + MG996R_TEETH),
             ("stall_torque_nmm", MG996R_DATASHEET), ("no_load_speed", MG996R_DATASHEET),
             ("voltage_v", MG996R_DATASHEET)),
    gaps=(("rated_torque_nmm", "the datasheet (Handsontec EMH-1056) gives the stall torque only, at 4.8 V and 6 V; "
                               "no continuous or rated torque"),
          ("horn", "no text source dimensions the horns supplied with the MG996R (hub, socket depth, arm-hole "
                   "radii): the datasheet shows them in its drawing only; Kartchner's servohorn_lib measures 20T "
                   "and 3F horns but no MG996R horn; alexandrepires5/HRManipulator CAD/measures.scad models an "
                   "MG946R horn without its socket or hole radii")),
)

# ---------------------------------------------------------------------------------------------------------
# Micro metal gearmotor (N20 class): Pololu 100:1 LP 6V, items #992 / #2204
# ---------------------------------------------------------------------------------------------------------

POLOLU_DATASHEET = ("Pololu 'Micro Metal Gearmotors' datasheet Rev 2.0 (May 2018), p. 1 and performance summary "
                    "(https://www.scribd.com/document/398291306/pololu-micro-metal-gearmotors-pdf): LP 6V, items "
                    "992/2204, 100.37:1: no load 130 RPM; at maximum efficiency 1.7 kg·mm; stall 7.4 kg·mm; "
                    "'L = 9 mm for all gear ratios except 1000:1'; 'Max length for M1.6 mounting screws is 1.3 mm'")
POLOLU_PRODUCT = ("Pololu product 5215 page (https://www.pololu.com/product/5215): 'gearbox cross section of 10×12 mm "
                  "and a 9 mm long, 3 mm diameter D-shaped gearbox output shaft' (the whole family)")

N20_DFLAT = ("salamanders/balance_bot, printed_parts/dcmotor.scad (https://github.com/salamanders/balance_bot), "
             "an N20 modelled for a D-bore hub: 'shaft_diameter = 3.0'; 'The \"D\" thickness (Distance from flat "
             "surface to opposite curved wall) For a 3mm shaft, this is usually 2.5mm. Measure yours with "
             "calipers!' 'shaft_flat_thickness = 2.5' (as modelled for the N20 class, not Pololu's drawing)")

N20 = Actuator(
    key="n20", name="Pololu micro metal gearmotor 100:1 LP 6V (N20 class)", kind="gearmotor",
    # the text gives the gearbox (10×12 mm cross-section, POLOLU_PRODUCT; L = 9 mm long, POLOLU_DATASHEET,
    # L varying with the ratio) but neither the motor can's length nor where the shaft sits in the 10×12
    body=None,
    mounting_holes=None,
    spline=None, horn=None,
    shaft=Shaft(diameter_mm=3.0, length_mm=9.0, flats=1,  # POLOLU_PRODUCT: Ø3 D-shaped, 9 mm long
                across_flats_mm=2.5,  # N20_DFLAT: flat to the far side 2.5 mm, as modelled (a modeller's value)
                flat_length_mm=None),
    rated_torque_nmm=1.7 * KGF_MM_NMM,  # POLOLU_DATASHEET: 1.7 kg·mm at maximum efficiency
    stall_torque_nmm=7.4 * KGF_MM_NMM,  # POLOLU_DATASHEET: stall extrapolation 7.4 kg·mm
    rated_force_n=None, stall_force_n=None,
    no_load_speed=rpm_to_deg_s(130.0),  # POLOLU_DATASHEET: no load 130 RPM
    voltage_v=6.0,  # POLOLU_DATASHEET: rated voltage 6 V (LP 6V)
    stroke_mm=None, closed_length_mm=None,
    sources=(("shaft", POLOLU_PRODUCT + "; across the flat: " + N20_DFLAT),
             ("rated_torque_nmm", POLOLU_DATASHEET + " (the torque at maximum efficiency taken as rated)"),
             ("stall_torque_nmm", POLOLU_DATASHEET), ("no_load_speed", POLOLU_DATASHEET),
             ("voltage_v", POLOLU_DATASHEET)),
    gaps=(("body", "gearbox 10×12 mm (product page) × 9 mm (datasheet L); the motor can's length and the "
                   "shaft's place in the gearbox section are on Pololu's datasheet drawing only. The public "
                   "models found are of other N20-class motors (a round gearbox, 'n20_reductor_dia = 14', in "
                   "K. Aziiev's OpenSCAD car parameters.scad; a bare 10×12 block in salamanders/balance_bot "
                   "dcmotor.scad): none gives the Pololu can or the shaft's offset"),
          ("mounting_holes", "two M1.6 tapped holes in the gearbox face (datasheet text: 'Max length for M1.6 "
                             "mounting screws is 1.3 mm'); their spacing and place are on the drawing only, and "
                             "no public model or text found states them"),
          ("shaft.flat_length_mm", "the flat's length is on Pololu's drawing only; the model giving the flat's "
                                   "depth (N20_DFLAT) cuts it along the whole shaft without stating a length")),
)

# ---------------------------------------------------------------------------------------------------------
# Steppers: NEMA 17 (17HS4401), 28BYJ-48
# ---------------------------------------------------------------------------------------------------------

NOP_NEMA = ("NopSCADlib vitamins/stepper_motors.scad, row NEMA17M (side 42.3, length 40, boss radius 11, boss depth "
            "2, shaft 5, shaft length 20, holes 31) (https://github.com/nophead/NopSCADlib)")
NEMA_FRAME = ("42 mm frame drawing (SS2421 datasheet hosted by TI E2E, https://e2e.ti.com/cfs-file/__key/"
              "communityserver-discussions-components-files/38/motor-2.pdf): 42 square, 2-31 hole pitch, 2-M3×0.5, "
              "Ø22 pilot, Ø5 shaft")
HS4401 = ("17HS4401 row '17HS4401 1.8 40 1.7 1.5 2.8 40 2.2 54 4 280' (MotionKing; https://gist.github.com/"
          "robertcedwards/3b47f0d5af4cdd30dad80279c71fd15a, from datasheetcafe.com 17hs4401-datasheet): 40 mm "
          "long, holding torque 40 N·cm; a shop listing names it 'NEMA 17 Stepper Motor 1.8° 40Ncm (17HS4401)'")

NEMA17 = Actuator(
    key="nema17", name="NEMA 17 stepper 17HS4401 (42 × 42 × 40 mm)", kind="stepper",
    body=(Box(-21.15, -21.15, -40.0, 21.15, 21.15, 0.0),  # NOP_NEMA side 42.3, length 40 (HS4401: 40 mm)
          Box(-11.0, -11.0, 0.0, 11.0, 11.0, 2.0)),  # NOP_NEMA boss radius 11, depth 2 (NEMA_FRAME Ø22)
    mounting_holes=tuple(Hole(sx * 15.5, sy * 15.5, 0.0, 3.0, "M3")  # NOP_NEMA holes 31; NEMA_FRAME 2-M3, 31
                         for sx in (-1.0, 1.0) for sy in (-1.0, 1.0)),  # the four corners of the 31 square
    spline=None, horn=None,
    shaft=Shaft(diameter_mm=5.0, length_mm=20.0, flats=None, across_flats_mm=None,  # NOP_NEMA shaft 5, length 20
                flat_length_mm=None),
    rated_torque_nmm=None,
    stall_torque_nmm=40.0 * 10.0,  # HS4401: holding torque 40 N·cm = 400 N·mm
    rated_force_n=None, stall_force_n=None,
    no_load_speed=None, voltage_v=None, stroke_mm=None, closed_length_mm=None,
    sources=(("body", f"{NOP_NEMA}; {NEMA_FRAME}; length: {HS4401}"),
             ("mounting_holes", f"{NOP_NEMA}; {NEMA_FRAME}"), ("shaft", f"{NOP_NEMA}; {NEMA_FRAME}"),
             ("stall_torque_nmm", HS4401 + " (holding torque, the most the stepper holds at standstill)")),
    gaps=(("rated_torque_nmm", "no pull-out (pull-out torque over speed) curve or table for the 17HS4401 was "
                               "found in text; it depends on the driver's voltage and current as well"),
          ("no_load_speed", "a stepper's speed is set by its driver"),
          ("voltage_v", "the HS4401 row gives 1.7 A and 1.5 Ω a phase, no rated voltage; the public notes "
                        "disagree (one test repository drives it as '3.8V/1.5A'), so none is entered"),
          ("shaft.flats", "NEMA 17 frames ship with round or D-cut 5 mm shafts, and no text found says which the "
                          "17HS4401 has: the generic models differ (NopSCADlib NEMA17M round; AuroraSCAD "
                          "motor.scad motortype_NEMA17 a flat 4.5 across). A flat in the catalogue would cut a "
                          "D-bore that a round-shafted motor cannot enter, so the bore stays round"),
          ("shaft.across_flats_mm", "no D-flat stated for the 17HS4401 (see shaft.flats)"),
          ("shaft.flat_length_mm", "no D-flat stated for the 17HS4401 (see shaft.flats)")),
)

NOP_28BYJ = ("NopSCADlib vitamins/geared_steppers.scad, row 28BYJ_48 (can Ø28 × 19, screw pitch 35, lug width 7 and "
             "thickness 0.85, hole 4.2, shaft offset 8, boss Ø9 × 1.5, shaft Ø5, 3 across the flats (negative: two "
             "flats), shaft length 10, flat length 6, wire bulge 14.7 wide to 17 from the can centre, 16.5 high) and "
             "vitamins/geared_stepper.scad (the layout) (https://github.com/nophead/NopSCADlib)")
KIATRONICS_28BYJ = ("Kiatronics '28BYJ-48 – 5V Stepper Motor' datasheet (https://github.com/neutmute/RPi.Demo/blob/"
                    "master/Datasheets/28BYJ-48_Stepper.pdf): rated voltage 5 VDC, speed variation ratio 1/64, "
                    "stride angle 5.625°/64, frequency 100 Hz, self-positioning torque >34.3 mN·m, pull in torque "
                    "300 gf·cm")

BYJ48 = Actuator(
    key="28byj48", name="28BYJ-48 5 V geared stepper", kind="stepper",
    body=(Box(-14.0, -22.0, -19.0, 14.0, 6.0, 0.0),  # NOP_28BYJ can Ø28 × 19, centre 8 from the shaft
          Box(-21.0, -11.5, -0.85, 21.0, -4.5, 0.0),  # NOP_28BYJ lugs: Ø7 ends at x ±17.5, 0.85 thick
          Box(-7.35, -25.0, -16.5, 7.35, -19.0, 0.0),  # NOP_28BYJ bulge 14.7 wide, to 17 from centre, 16.5 high
          Box(-4.5, -4.5, 0.0, 4.5, 4.5, 1.5)),  # NOP_28BYJ boss Ø9 × 1.5
    mounting_holes=(Hole(-17.5, -8.0, 0.0, 4.2), Hole(17.5, -8.0, 0.0, 4.2)),  # NOP_28BYJ pitch 35, Ø4.2, offset 8
    spline=None, horn=None,
    shaft=Shaft(diameter_mm=5.0, length_mm=10.0, flats=2, across_flats_mm=3.0,  # NOP_28BYJ Ø5, 3 A/F, 10 long
                flat_length_mm=6.0),  # NOP_28BYJ flat length 6
    rated_torque_nmm=300.0 * GF_CM_NMM,  # KIATRONICS: pull in torque 300 gf·cm
    stall_torque_nmm=34.3,  # KIATRONICS: self-positioning torque > 34.3 mN·m = 34.3 N·mm
    rated_force_n=None, stall_force_n=None,
    no_load_speed=100.0 * 5.625 / 64.0,  # KIATRONICS: 100 Hz × 5.625°/64 a step = 8.79 °/s at the output
    voltage_v=5.0,  # KIATRONICS: rated voltage 5 VDC
    stroke_mm=None, closed_length_mm=None,
    sources=(("body", NOP_28BYJ), ("mounting_holes", NOP_28BYJ), ("shaft", NOP_28BYJ),
             ("rated_torque_nmm", KIATRONICS_28BYJ + " (pull-in torque taken as rated)"),
             ("stall_torque_nmm", KIATRONICS_28BYJ + " (self-positioning torque, a lower bound)"),
             ("no_load_speed", KIATRONICS_28BYJ + " (derived: frequency × stride angle)"),
             ("voltage_v", KIATRONICS_28BYJ)),
)

# ---------------------------------------------------------------------------------------------------------
# Off-board tendon / push rod; linear actuator (Actuonix L16-R)
# ---------------------------------------------------------------------------------------------------------

TENDON = Actuator(
    key="tendon", name="tendon or push rod driven from off-board", kind="tendon",
    body=(), mounting_holes=(), spline=None, horn=None, shaft=None,
    rated_torque_nmm=None, stall_torque_nmm=None, rated_force_n=None, stall_force_n=None,
    no_load_speed=None, voltage_v=None, stroke_mm=None, closed_length_mm=None,
    sources=(),
    gaps=(("rated_force_n", "an off-board drive: the template states the force (tendon(force_n))"),),
)


def tendon(force_n: float, stroke_mm: float | None = None) -> Actuator:
    """The off-board tendon or push rod rated at the template's ``force_n`` (N)."""
    try:
        f = float(force_n)
    except (TypeError, ValueError):
        raise SpecError("force_n", f"expected a number, got {force_n!r}") from None
    if not (f > 0.0 and f < float("inf")):
        raise SpecError("force_n", f"expected a positive finite force, got {force_n!r}")
    sources = [("rated_force_n", "template parameter [actuator] force_n")]
    if stroke_mm is not None:
        sources.append(("stroke_mm", "template parameter [actuator] stroke_mm"))
    return dataclasses.replace(TENDON, rated_force_n=f, stroke_mm=None if stroke_mm is None else float(stroke_mm),
                               sources=tuple(sources), gaps=())


WCP_L16 = ("Actuonix L16-R (50 mm stroke, 63:1) figures from WCP 'Miniature Linear Servo Actuators — General Data' "
           "(https://docs.wcproducts.com/welcome/electronics/miniature-linear-servo-actuators/general-info/"
           "general-data): 63:1 peak power point 75 N @ 10 mm/s, max speed (no load) 20 mm/s, max force (lifted) "
           "100 N; 50 mm stroke: closed length (hole to hole) 118 mm; input voltage 6 VDC")
ACTUONIX_L16_OPTIONS = ("Actuonix L16 datasheet Rev C, model selection (https://www.manualshelf.com/manual/actuonix/"
                        "l16-100-35-06-r/data-sheet-english/page-2.html): strokes 50/100/140 mm, ratios 35/63/150, "
                        "-R RC linear servo")

L16 = Actuator(
    key="l16", name="Actuonix L16-50-63-6-R linear servo", kind="linear",
    body=None,
    # rod-end hole at the origin (retracted), the rear clevis hole 118 mm behind it on the axis
    mounting_holes=None,
    spline=None, horn=None, shaft=None,
    rated_torque_nmm=None, stall_torque_nmm=None,
    rated_force_n=75.0,  # WCP_L16: 63:1 peak power point 75 N @ 10 mm/s
    stall_force_n=100.0,  # WCP_L16: 63:1 max force (lifted) 100 N
    no_load_speed=20.0,  # WCP_L16: 63:1 max speed (no load) 20 mm/s
    voltage_v=6.0,  # WCP_L16: input voltage 6 VDC
    stroke_mm=50.0,  # WCP_L16: stroke option 50 mm (ACTUONIX_L16_OPTIONS)
    closed_length_mm=118.0,  # WCP_L16: 50 mm stroke, closed length (hole to hole) 118 mm
    sources=(("rated_force_n", WCP_L16 + " (peak power point taken as rated)"),
             ("stall_force_n", WCP_L16), ("no_load_speed", WCP_L16), ("voltage_v", WCP_L16),
             ("stroke_mm", f"{WCP_L16}; {ACTUONIX_L16_OPTIONS}"), ("closed_length_mm", WCP_L16)),
    gaps=(("body", "the case cross-section is on the Actuonix datasheet drawing (last page) only: the "
                   "datasheet text (Rev C, model selection and wiring) and the WCP L16 pages state stroke, "
                   "ratios, forces, speeds and the closed length, not the case section; no public model of the "
                   "L16 with its section was found"),
          ("mounting_holes", "the clevis and rod-end hole diameters are on the datasheet drawing only (their "
                             "spacing, 118 mm closed, is closed_length_mm); the one text found giving a clevis "
                             "hole (Ø3.0, 'accepts M3') gives the L16 a 35 N maximum force, contradicting WCP's "
                             "63:1 figures, so it is not used")),
)

#: The catalogue, by key. Complete (body, mount, interface, rating): sg90, mg90s, mg996r, nema17, 28byj48
#: (and the tendon, once its force is given); n20 and l16 lack the body and mount their drawings alone give.
CATALOGUE: dict[str, Actuator] = {a.key: a for a in (SG90, MG90S, MG996R, N20, NEMA17, BYJ48, TENDON, L16)}


def actuator(key: str) -> Actuator:
    """The catalogue entry ``key`` (SpecError naming ``actuator`` if there is none)."""
    if key not in CATALOGUE:
        raise SpecError("actuator", f"no actuator {key!r} in the catalogue; keys {', '.join(CATALOGUE)}")
    return CATALOGUE[key]
