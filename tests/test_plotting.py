"""The shared plot helpers (``fabricate/plotting.py``): distinct series colours, legends never below the stated
size, the readability rules every plot is held to, and deterministic PNG bytes. The plots a build writes are
held to the same rules in tests/export/test_previews.py (every shipped template)."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from fabricate.plotting import (
    DISTINCT_HEX,
    MIN_LEGEND_PT,
    figure,
    figure_problems,
    legend,
    palette,
    png_bytes,
    rounded_xy,
    series_colours,
    series_styles,
)


def _distance(a: tuple[float, ...], b: tuple[float, ...]) -> float:
    return float(np.linalg.norm(np.subtract(a[:3], b[:3])))


@pytest.mark.parametrize("n", [1, 2, 10, 11, 12, 20, len(DISTINCT_HEX), len(DISTINCT_HEX) + 1, 120])
def test_palette_colours_are_pairwise_distinct(n):
    colours = palette(n)
    assert len(colours) == n
    assert len(set(colours)) == n
    assert all(0.0 <= c <= 1.0 for rgb in colours for c in rgb)
    # the written-out ones are far apart: the eleventh is not the first blue again
    far = colours[:len(DISTINCT_HEX)]
    assert all(_distance(a, b) >= 0.15 for a, b in itertools.combinations(far, 2))


def test_palette_order_is_fixed_and_starts_with_tab10():
    assert palette(5) == palette(40)[:5]  # a plot of 5 series and one of 40 agree on the first five
    assert palette(3) == palette(3)
    assert palette(1)[0] == pytest.approx((0x1F / 255, 0x77 / 255, 0xB4 / 255))  # tab:blue
    assert palette(11)[10] != palette(11)[0]


def test_series_styles_change_line_style_with_each_decade():
    styles = series_styles(25)
    assert len({tuple(s["color"]) for s in styles}) == 25
    assert {s["linestyle"] for s in styles[:10]} == {"-"}
    assert {s["linestyle"] for s in styles[10:20]} == {"--"}
    assert styles[20]["linestyle"] == "-."


def _two_lines(**style_b: object) -> tuple[object, object]:
    fig = figure((4.0, 3.0), 100)
    ax = fig.add_subplot(1, 1, 1)
    x = np.linspace(0.0, 1.0, 5)
    ax.plot(x, x, color="tab:blue", label="root")
    ax.plot(x, 2 * x, label="tip", **{"color": "tab:orange", **style_b})
    return fig, ax


def test_legend_text_is_never_below_the_minimum():
    fig, ax = _two_lines()
    leg = legend(ax, fontsize=5)  # asked smaller: raised
    assert min(t.get_fontsize() for t in leg.get_texts()) == MIN_LEGEND_PT
    leg = legend(ax, fontsize=11)  # asked larger: kept
    assert min(t.get_fontsize() for t in leg.get_texts()) == 11
    assert MIN_LEGEND_PT >= 8.0  # 11 px at the plots' 100 dpi
    assert figure_problems(fig) == []


def test_figure_problems_names_a_small_legend():
    fig, ax = _two_lines()
    ax.legend(fontsize=6)
    assert any("6 pt" in p for p in figure_problems(fig))


def test_figure_problems_names_series_drawn_alike():
    fig, ax = _two_lines(color="tab:blue")  # root and tip both blue
    legend(ax)
    problems = figure_problems(fig)
    assert any("'root' and 'tip' are drawn alike" in p for p in problems), problems
    assert series_colours(ax)[0] == series_colours(ax)[1]
    fig, ax = _two_lines(color="tab:blue", linestyle="--")  # one colour, told apart by the dashes: readable
    legend(ax)
    assert figure_problems(fig) == []


def test_figure_problems_names_a_missing_legend():
    fig, ax = _two_lines()
    assert any("in no legend" in p for p in figure_problems(fig))
    fig = figure((4.0, 3.0), 100)
    ax = fig.add_subplot(1, 1, 1)
    for colour in ("tab:blue", "tab:orange"):  # two curves, nothing says which is which
        ax.plot([0, 1, 2], [0, 1, 0], color=colour)
    assert any("no legend" in p for p in figure_problems(fig))
    fig = figure((4.0, 3.0), 100)
    ax = fig.add_subplot(1, 1, 1)
    ax.plot([0, 1, 2], [0, 1, 0], color="tab:blue")
    ax.plot([0, 1, 2], [1, 1, 1], color="0.5")  # one curve and a grey guide: no legend needed
    assert figure_problems(fig) == []


def test_png_bytes_are_deterministic():
    def draw() -> bytes:
        fig, ax = _two_lines()
        legend(ax)
        return png_bytes(fig)

    first, second = draw(), draw()
    assert first == second and first.startswith(b"\x89PNG\r\n\x1a\n")
    assert b"Software" not in first and b"matplotlib" not in first.lower()


def test_strength_plot_gives_each_of_twelve_parts_its_own_colour():
    from fabricate.strength.check import StrengthResult
    from fabricate.strength.features import Finding
    from fabricate.strength.plots import MAX_PARTS, strength_figure

    x = np.linspace(0.0, 360.0, 50)
    feature = "section at hole G1+G1r: N -20.0 N, M -254 N·mm (Kt 2.23)"  # as long as the plot's entries get
    findings = [Finding(part=f"part_{k:02d}", feature=feature, kind="link", stress_MPa=1.0 + k,
                        allowable_MPa=40.0, pose=0, load="design", fix="", curve=(1.0 + k) * np.sin(np.radians(x)) ** 2)
                for k in range(14)]
    result = StrengthResult(findings=findings, statics=None, min_safety_factor=2.0, inputs=x)
    fig = strength_figure(result, "deg")
    ax = fig.axes[0]
    colours = series_colours(ax)
    assert len(colours) == MAX_PARTS + 1  # the parts drawn and the limit line
    assert len(set(colours[:MAX_PARTS])) == MAX_PARTS  # root and tip no longer both blue
    assert figure_problems(fig) == []
    # every entry whole: the legend inside the figure (beside the axes it ran past the right edge)
    fig.canvas.draw()
    box = (fig.legends[0] if fig.legends else ax.get_legend()).get_window_extent()
    assert box.x0 >= 0 and box.y0 >= 0 and box.x1 <= fig.bbox.x1 and box.y1 <= fig.bbox.y1
    assert png_bytes(strength_figure(result, "deg")) == png_bytes(strength_figure(result, "deg"))


def test_gear_law_plot_has_a_legend_naming_both_curves():
    from fabricate.export.gear_plots import law_figure

    def law(x, derivative=0):
        x = np.asarray(x, dtype=float)
        return -0.5 * x - 0.1 * np.sin(x) if derivative == 0 else -0.5 - 0.1 * np.cos(x)

    fig = law_figure(law, (0.0, 2.0), 30.0)
    texts = [t.get_text() for ax in fig.axes if ax.get_legend() for t in ax.get_legend().get_texts()]
    assert any("driven angle" in t for t in texts) and any("ratio" in t for t in texts)
    assert figure_problems(fig) == []


def test_rounded_xy_gives_pythons_round_of_every_coordinate():
    # the GIFs' bytes depend on these floats: numpy's rint(100 v) / 100 differs from round(v, 2) where 100 v
    # rounds across a half (2.675 * 100 = 267.49999999999997; 1.005, 0.285 ...): every such value is here, and
    # long arrays (the vectorised route) as well as a single point
    rng = np.random.default_rng(7)
    halves = np.arange(0, 40000) / 100.0 + 0.005  # k.kk5: the ties in decimal, none exact in binary
    for x in (halves, rng.uniform(-20.0, 500.0, 5000), np.array([2.675]), np.array([-0.004, 1.005])):
        y = x[::-1] * 0.5
        got = rounded_xy(x, y)
        want = [v for a, b in zip(x, y, strict=True) for v in (round(float(a), 2), round(float(b), 2))]
        assert got == want
        assert all(type(v) is float for v in got)
    # the float products and numpy's own rounding do disagree on some of them (the case handled above)
    assert np.any(np.rint(halves * 100.0) / 100.0 != np.array([round(float(v), 2) for v in halves]))
