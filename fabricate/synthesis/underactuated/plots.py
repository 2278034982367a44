"""Figures of the underactuated finger: closing on the cylinder, joint angles against stroke."""

from __future__ import annotations

import numpy as np

from fabricate.plotting import figure, legend, palette, png_bytes


def _png(fig) -> bytes:
    return png_bytes(fig, 110)


def closing_figures(spec, motion, free, final) -> dict[str, bytes]:
    """``{file name: PNG bytes}``: closing.png (poses on the object), joint_angles.png."""
    from matplotlib.patches import Circle

    from fabricate.synthesis.underactuated.model import finger_pose

    d = spec.design
    out: dict[str, bytes] = {}
    fig = figure((6, 5), 100)  # matplotlib's default dpi, as pyplot's figures had
    ax = fig.subplots()
    ax.add_patch(Circle(spec.cylinder_centre, spec.cylinder_radius, color="0.85"))
    # one colour per pose (palette order: pose indices ten apart shared a colour), named by its stroke
    shown = np.linspace(0, len(motion.strokes) - 1, 5).astype(int)
    for k, colour in zip(shown, palette(len(shown)), strict=True):
        pose = finger_pose(d, motion.q[k])
        assert pose is not None  # the closing motion only holds poses that close
        ax.plot(pose.G[:, 0], pose.G[:, 1], "-o", ms=3, lw=2, color=colour, label=f"stroke {motion.strokes[k]:.1f} mm")
        for i in range(d.n - 1):
            ax.plot([pose.G[i, 0], pose.Q[i, 0], pose.P[i, 0]], [pose.G[i, 1], pose.Q[i, 1], pose.P[i, 1]],
                    ":", lw=0.8, color=colour)
        ax.plot([pose.S[0], pose.K[0]], [pose.S[1], pose.K[1]], "--", lw=0.8, color=colour)
    pts = final["points"]
    ax.plot(pts[:, 0], pts[:, 1], "kx", label="contact points")
    ax.set_aspect("equal")
    order = ", ".join(f"phalanx {i + 1}" for i in motion.contact_order)
    ax.set_title(f"closing on the cylinder; contact order: {order}")
    ax.set_xlabel("x (mm)")
    ax.set_ylabel("y (mm)")
    legend(ax, loc="best", framealpha=0.85)
    out["closing.png"] = _png(fig)

    fig = figure((6, 4), 100)  # matplotlib's default dpi, as pyplot's figures had
    ax = fig.subplots()
    # a joint's colour is shared by its two curves (solid on the object, dashed free): distinct per joint
    for i, colour in enumerate(palette(d.n)):
        ax.plot(motion.strokes, np.degrees(motion.q[:, i]), color=colour, label=f"joint {i + 1}, on object")
        ax.plot(free.strokes, np.degrees(free.q[:, i]), "--", color=colour, label=f"joint {i + 1}, free")
    for s in motion.contact_strokes:
        ax.axvline(s, color="grey", lw=0.6)
    ax.set_xlabel("push-rod stroke (mm)")
    ax.set_ylabel("relative joint angle (deg)")
    legend(ax)
    out["joint_angles.png"] = _png(fig)
    return out
