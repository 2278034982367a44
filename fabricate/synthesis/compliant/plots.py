"""Figures of the compliant gripper: grasp force against stroke (paper Fig 3), closing poses."""

from __future__ import annotations

import numpy as np

from fabricate.plotting import figure, legend, palette, png_bytes


def _png(fig) -> bytes:
    return png_bytes(fig, 110)


def compliant_figures(spec, path, grasp, motion, optimum) -> dict[str, bytes]:
    """``{file name: PNG bytes}``: grasp_force.png (Fig 3) and closing.png (finger poses)."""
    from matplotlib.patches import Circle

    from fabricate.synthesis.compliant.model import finger_state, grasp_force_curve

    out: dict[str, bytes] = {}
    strokes, f_static, f_hover = grasp_force_curve(path, spec.springs, spec.load.mu)
    fig = figure((6, 4), 100)  # matplotlib's default dpi, as pyplot's figures had
    ax = fig.subplots()
    static_colour, hover_colour = palette(2)
    ax.plot(strokes, f_static, color=static_colour, label="static load F_n1 (eqs 3-4)")
    ax.plot(strokes, f_hover, "--", color=hover_colour, label="hover F_n (eqs 5-6)")
    ax.axhline(spec.load.hover_force, color="grey", lw=0.8)
    ax.axvline(grasp.stroke, color="grey", lw=0.8)
    ax.plot([grasp.stroke], [grasp.fn_static], "o", color=static_colour)
    ax.annotate(f"F_n1 = {grasp.fn_static:.2f} N\nF_n2 = {grasp.fn_hover:.2f} N",
                (grasp.stroke, grasp.fn_static), textcoords="offset points", xytext=(8, -30))
    ax.set_xlim(strokes[0] if len(strokes) else 0, grasp.stroke + 4.0)
    ax.set_ylim(0, max(2.5 * spec.load.hover_force, 1.0))
    ax.set_xlabel("drive rod stroke (mm)")
    ax.set_ylabel("grasp force (N)")
    ax.set_title(f"D = {spec.load.diameter:g} mm can: grasp force against stroke")
    legend(ax, loc="upper left")
    out["grasp_force.png"] = _png(fig)

    fig = figure((5, 6), 100)  # matplotlib's default dpi, as pyplot's figures had
    ax = fig.subplots()
    g = spec.geometry
    # one colour per pose (palette order, not the pose's index: two indices ten apart shared a colour), named
    # by its stroke in the legend
    shown = np.linspace(0, len(motion.strokes) - 1, 6).astype(int)
    for k, colour in zip(shown, palette(len(shown)), strict=True):
        st = finger_state(g, motion.phi1[k], motion.phi2[k])
        pts = np.array([[0.0, 0.0], st.B, st.C, st.D, st.E, st.M])
        ax.plot(pts[:5, 0], pts[:5, 1], "-o", ms=3, color=colour, label=f"stroke {motion.strokes[k]:.1f} mm")
        ax.plot(pts[4:, 0], pts[4:, 1], ":", color=colour)
        circ = Circle((float(st.pad_centre[0]), float(st.pad_centre[1])), g.r, fill=False, lw=0.5, color=colour)
        ax.add_patch(circ)
    wall = spec.load.radius - g.l1
    ax.axvline(wall, color="k", lw=1.5)
    ax.set_aspect("equal")
    ax.set_xlabel("x from finger mount (mm)")
    ax.set_ylabel("y (mm)")
    title = "closing on the can"
    if optimum is not None:
        title += f"\noptimum dN = {optimum.delta_n:.3f} N"
    ax.set_title(title)
    legend(ax, loc="best", framealpha=0.85)
    out["closing.png"] = _png(fig)
    return out
