"""A design template, validated: :class:`DesignSpec` and the glue that reads one (:func:`load_design`).

A template is a TOML file (found and read by :mod:`fabricate.templates`). Each of its tables is read by its
own parser through :class:`fabricate.table.Table`, a strict reader whose every error names the field path
and what was expected; this module reads the generic sections and hands every other table to the kind's
parser. Nothing here writes files.

Generic sections
----------------
``[design]``   name, kind (selects the synthesis method), description.
``[process]``  profile (a shipped ``templates/process_<profile>.toml``: ``"sla"``, ``"laser"``...) and any
               field of that profile to override (:mod:`fabricate.process`).
``[checks]``   sweep_poses, min_clearance_mm, min_safety_factor.
``[gears]``, ``[parts]``, ``[load]``, ``[actuator]``  read by :mod:`fabricate.gears.spec`,
               :mod:`fabricate.parts.spec`, :mod:`fabricate.strength.spec`, :mod:`fabricate.drive.spec`.
Every other top-level table belongs to the kind's parser.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from fabricate.errors import SpecError
from fabricate.process import ProcessOverride, ProcessSpec
from fabricate.table import Table

if TYPE_CHECKING:  # the sections' parsers import this module's neighbours: names for the checker only
    from fabricate.drive.spec import ActuatorSpec
    from fabricate.gears.spec import GearSpec
    from fabricate.parts.spec import PartsSpec
    from fabricate.strength.spec import LoadSpec


@dataclass(frozen=True)
class ChecksSpec:
    """``[checks]``: sweep resolution and pass thresholds."""

    sweep_poses: int = 360
    min_clearance_mm: float | None = None  # None: the process's running clearance
    min_safety_factor: float = 2.0  # every part's strength: allowable stress / stress at the design load


def parse_checks(table: Table) -> ChecksSpec:
    """Read ``[checks]``; ``sweep_poses`` is bounded by :data:`fabricate.bounds.MAX_SWEEP_POSES`."""
    from fabricate.bounds import MAX_SWEEP_POSES

    spec = ChecksSpec(
        sweep_poses=table.integer("sweep_poses", 360, min=2, max=MAX_SWEEP_POSES),
        min_clearance_mm=table.number("min_clearance_mm", None, min=0.0, max=50.0),
        min_safety_factor=table.number("min_safety_factor", 2.0, min=1.0, max=20.0),
    )
    table.finish()
    return spec


#: Longest design name: it names the output folder (plus "-synth" or "-sweep" and fabricate's temporary
#: siblings' suffix), which must stay within a file system's 255 bytes per name.
MAX_NAME_CHARS = 100
MAX_NAME_BYTES = 200
#: Characters no design name may hold: path separators, and those Windows refuses in a folder name.
_NAME_FORBIDDEN = '/\\:*?"<>|'


def check_design_name(name: str, path: str = "design.name") -> str:
    """A design name that is safe as a folder name on every platform, else a :class:`SpecError` at ``path``.

    Refused: an empty name, ``.``/``..`` or any name starting with ``.`` (a hidden folder), leading or trailing
    spaces and a trailing ``.`` (Windows drops them), control characters (NUL included), line separators, lone
    surrogates, the characters ``/ \\ : * ? " < > |``, and more than :data:`MAX_NAME_CHARS` characters or
    :data:`MAX_NAME_BYTES` bytes of UTF-8.
    """
    import unicodedata

    # as the user would type it in TOML, without writing a NUL or a control character to the terminal
    shown = '"' + "".join(c if c.isprintable() else f"\\u{ord(c):04X}" for c in name[:60]) \
        + ('..."' if len(name) > 60 else '"')
    if not name:
        raise SpecError(path, "expected a plain file name (it names the output folder), got an empty name")
    kinds = {"Cc": "control character", "Cs": "lone surrogate", "Zl": "line separator", "Zp": "paragraph separator"}
    bad = next((c for c in name if c in _NAME_FORBIDDEN or unicodedata.category(c) in kinds), None)
    why = ""
    if bad is not None:
        why = f'it holds "{bad}"' if bad in _NAME_FORBIDDEN else \
            f"it holds the {kinds[unicodedata.category(bad)]} U+{ord(bad):04X}"
    elif name.startswith("."):
        why = 'it starts with "." (a hidden folder, or the folder itself or its parent)'
    elif name.endswith(".") or name != name.strip():
        why = 'it ends with "." or has spaces at an end (Windows drops them from folder names)'
    if why:
        raise SpecError(path, f"expected a plain file name (it names the output folder), got {shown}: {why}")
    size = len(name.encode("utf-8"))
    if len(name) > MAX_NAME_CHARS or size > MAX_NAME_BYTES:
        raise SpecError(path, f"expected at most {MAX_NAME_CHARS} characters ({MAX_NAME_BYTES} bytes of UTF-8): it "
                              f"names the output folder; got {len(name)} characters ({size} bytes)")
    return name


@dataclass(frozen=True)
class DesignSpec:
    """A whole validated template.

    Attributes
    ----------
    name, kind, description : str
    template : Path
        Where it was read from.
    template_text : str
        The template exactly as validated (embedded in report.json so a build can be re-made from it).
    process_override : ProcessOverride or None
        The ``--process`` profile that replaced the template's, if any.
    process : ProcessSpec
    checks : ChecksSpec
    gears : fabricate.gears.spec.GearSpec
        ``[gears]``: module, pressure angle, method, backlash (defaults when the table is absent).
    parts : fabricate.parts.spec.PartsSpec
        ``[parts]``: pad, hub and mounting options (defaults when the table is absent).
    method : object
        The kind's own frozen spec (see :mod:`fabricate.synthesis`).
    load : fabricate.strength.spec.LoadSpec or None
        ``[load]`` (its defaults when the table is absent).
    actuator : fabricate.drive.spec.ActuatorSpec or None
        ``[actuator]``: the catalogue actuator that drives the design; None when the template names none.
    """

    name: str
    kind: str
    description: str
    template: Path
    process: ProcessSpec
    checks: ChecksSpec
    gears: GearSpec
    parts: PartsSpec
    method: Any  # the kind's own spec; each kind's entry points know its type
    template_text: str = ""
    process_override: ProcessOverride | None = None
    load: LoadSpec | None = None
    actuator: ActuatorSpec | None = None  # [actuator]: what drives the design (None: nothing named)
