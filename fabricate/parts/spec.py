"""The generic ``[parts]`` template table: how bodies become printable / cuttable parts.

Every template may carry a ``[parts]`` table; when it is absent the defaults below apply. Process
values (clearance, minimum wall, pin diameter, kerf) come from ``[process]``; this table only holds
choices about the part shapes and the layouts.

Keys (all optional)
-------------------
``link_width_mm``        float > 0, or ``"auto"``. Plate width of binary links. Absent: the synthesis hint
                         ``link_width_mm`` if any, else the boss diameter (pin hole + 2 × wall).
                         ``"auto"``: the smallest width (to 0.1 mm, up to :data:`MAX_AUTO_WIDTH_MM`) at
                         which every link section and hole keeps ``[checks] min_safety_factor`` at the
                         design load (``[load]``); the chosen width is in the report.
``boss_wall_mm``         float > 0. Radial wall around every pin hole. Absent: max(process min wall,
                         0.5 × pin diameter) so bosses are never thinner than the process allows.
``hub_diameter_mm``      float > 0. Hub of a gear fused to its body. Absent: ``[gears] hub_diameter_mm``
                         or the boss diameter.
``pad_radius_mm``        float > 0. Fingertip pad radius; overrides the synthesis hint.
``mounting_holes``       int in [0, 16], default 2. Mounting holes on the ground part.
``mounting_hole_mm``     float > 0, default 3.0. Nominal diameter of a mounting screw.
``plate_spacing_mm``     float >= 0, default 4.0. Gap between parts on the SLA print plate.
``sheet_margin_mm``      float >= 0, default 5.0. Margin at the sheet edge for the laser nesting.
``sheet_spacing_mm``     float >= 0, default 3.0. Gap between nested parts on the sheet.
``preview_poses``        int in [1, 24], default 4. Poses drawn in the assembly preview PNG.
``gif_frames``           int in [2, 360], default 24. Frames of the motion GIF.

Example
-------
.. code-block:: toml

    [parts]
    link_width_mm = 8.0
    mounting_holes = 3
"""

from __future__ import annotations

from dataclasses import dataclass

from fabricate.table import Table

#: Widest link ``link_width_mm = "auto"`` tries (mm): beyond it the design needs a thicker plate or a
#: stronger material, which the strength failure then says.
MAX_AUTO_WIDTH_MM = 60.0


@dataclass(frozen=True)
class PartsSpec:
    """Validated ``[parts]`` table. Lengths in mm; None means "derive from process / hints".

    Attributes
    ----------
    link_width_mm : float, None or "auto"
        Plate width of binary links ("auto": sized for strength by the pipeline).
    boss_wall_mm : float or None
        Radial wall around pin holes.
    hub_diameter_mm : float or None
        Hub diameter of fused gears.
    pad_radius_mm : float or None
        Fingertip pad radius override.
    mounting_holes : int
        Number of mounting holes on the ground part.
    mounting_hole_mm : float
        Nominal mounting screw diameter.
    plate_spacing_mm : float
        Gap between parts on the print plate.
    sheet_margin_mm, sheet_spacing_mm : float
        Sheet edge margin and part gap of the laser nesting.
    preview_poses : int
        Poses in the assembly PNG.
    gif_frames : int
        Frames of the motion GIF.
    """

    link_width_mm: float | str | None = None
    boss_wall_mm: float | None = None
    hub_diameter_mm: float | None = None
    pad_radius_mm: float | None = None
    mounting_holes: int = 2
    mounting_hole_mm: float = 3.0
    plate_spacing_mm: float = 4.0
    sheet_margin_mm: float = 5.0
    sheet_spacing_mm: float = 3.0
    preview_poses: int = 4
    gif_frames: int = 24


def parse_parts_spec(table: Table) -> PartsSpec:
    """Read the ``[parts]`` table (an empty table gives the defaults).

    Parameters
    ----------
    table : Table
        The ``[parts]`` table, ``{}`` when absent.

    Returns
    -------
    PartsSpec

    Raises
    ------
    SpecError
        On a field out of range or unknown, naming ``parts.<key>``.
    """
    auto = table.has("link_width_mm") and table.raw("link_width_mm") == "auto"
    spec = PartsSpec(
        link_width_mm="auto" if auto else table.number("link_width_mm", None, positive=True, max=500.0),
        boss_wall_mm=table.number("boss_wall_mm", None, positive=True, max=100.0),
        hub_diameter_mm=table.number("hub_diameter_mm", None, positive=True, max=1000.0),
        pad_radius_mm=table.number("pad_radius_mm", None, positive=True, max=200.0),
        mounting_holes=table.integer("mounting_holes", 2, min=0, max=16),
        mounting_hole_mm=table.number("mounting_hole_mm", 3.0, positive=True, max=50.0),
        plate_spacing_mm=table.number("plate_spacing_mm", 4.0, min=0.0, max=100.0),
        sheet_margin_mm=table.number("sheet_margin_mm", 5.0, min=0.0, max=200.0),
        sheet_spacing_mm=table.number("sheet_spacing_mm", 3.0, min=0.0, max=100.0),
        preview_poses=table.integer("preview_poses", 4, min=1, max=24),
        gif_frames=table.integer("gif_frames", 24, min=2, max=360),
    )
    table.finish()
    return spec
