"""The dimensioned drawing and the model picture (designer.outputs.drawing): what the drawing
states about the design, its shortened length axis and its hidden-surface rendering.
"""

from __future__ import annotations

import pytest

from designer.outputs import cad
from designer.outputs.drawing import picture, views
from shared_inputs import cad_record as record

MM = 1e-3


def drawing_texts(name: str) -> str:
    from designer.outputs import drawing

    fig = drawing.plot_drawing(cad.resolve(record(name)))
    return "\n".join(t.get_text() for t in fig.axes[0].texts)


def test_drawing_of_prototype_b_gives_stations_lengths_holes_material_and_name():
    texts = drawing_texts("prototype_b").splitlines()
    for expected in ["20", "60", "100",            # stations from the clamp face
                     "450", "475", "25",           # free length, overall, clamp block
                     "12.7", "Ø9.5",               # section, hole in the section view
                     "3x Ø9.5 THRU", "2x Ø4.5 THRU (M4 CLEARANCE)", "6.25", "12.5",
                     "2024-T3", "prototype-b"]:
        assert expected in texts, expected


def test_drawing_of_slot_pockets_gives_pocket_length_width_depth_and_tool():
    texts = drawing_texts("rect_pockets")
    lines = texts.splitlines()
    for expected in ["8.9", "5.5", "1", "20", "8", "80", "112.5", "145"]:
        assert expected in lines, expected
    assert "SLOT 8.9 x 5.5 x 1 DEEP, R1.5 CORNERS (Ø3 END MILL)" in texts
    assert "WIRE CHANNEL 1.5 WIDE x 0.5 DEEP" in texts
    # the root a half circle of half the width, the U-notch the beam model's K_t is of (docs/model.md §4)
    assert "3x LOAD GROOVE 0.5 WIDE x 0.3 DEEP, R0.25 FULL-RADIUS ROOT, ALL AROUND" in texts


def test_a_stock_design_s_drawing_names_its_stock_item_and_a_bad_one_is_refused():
    """The section of a stock design is the supplier's: the notes name the item as design.json
    records it; a design without stock names none; a stock entry without its label is refused."""
    from designer.errors import DesignFileError
    from designer.outputs import drawing

    r = record("prototype_b")
    label = "flat bar 1/2 × 1/2 in (ASTM B211 / B221)"
    r["design"]["stock"] = {"label": label, "shape": "square bar"}
    fig = drawing.plot_drawing(cad.resolve(r))
    assert f"Stock: {label}; its section is used as supplied." in "\n".join(t.get_text() for t in fig.axes[0].texts)
    assert "Stock:" not in drawing_texts("prototype_b")
    r["design"]["stock"] = {"shape": "square bar"}
    with pytest.raises(DesignFileError, match="design.stock"):
        cad.resolve(r)


def test_drawing_of_flats_gives_across_flats_and_bore():
    lines = drawing_texts("tube_flats").splitlines()
    for expected in ["18", "Ø15", "Ø20", "(8.72)", "20", "50", "80", "200"]:
        assert expected in lines, expected   # 20 - 2 x 1 across flats; chord 2 sqrt(10^2 - 9^2) = 8.72


def test_long_plain_runs_are_broken_and_the_axis_keeps_order():
    a = views.length_axis(cad.resolve(record("prototype_a")))
    assert len(a.gaps) == 1                                  # 123 -> 800 mm shortened
    assert a(0.02) < a(0.12) < a(0.5) < a(0.8)
    p = views.length_axis(cad.resolve(record("rect_pockets")))
    assert p.gaps == ()                                      # short runs stay to scale
    assert p(0.1) - p(0.0) == pytest.approx(100 * p.scale)


def test_depth_buffer_keeps_the_nearer_triangle():
    import numpy as np

    # two triangles over the same 10 x 10 pixel square at depths 1 and 2 (larger is nearer)
    square = np.array([[0, 0], [10, 0], [0, 10]], float)
    xy = np.stack([square, square])
    depth = np.array([[1.0, 1.0, 1.0], [2.0, 2.0, 2.0]])
    z = picture._zbuffer(xy, depth, np.zeros(2), 1.0, (12, 12))
    covered = np.isfinite(z)
    assert np.all(z[covered] == 2.0)
    # the lower-left half of the square: pixel centres with x + y < 10 -> 45 pixels (+ 10 on the diagonal)
    assert 45 <= covered.sum() <= 55
    assert not covered[11, 11]


@pytest.mark.slow
def test_model_picture_draws_both_panels():
    from designer.outputs import drawing

    beam = cad.resolve(record("prototype_b"))
    fig = drawing.plot_model(cad.model_meshes(beam, cad.build_solid(beam)), beam)
    assert len(fig.axes) == 2                                 # whole beam and the close-up
    assert all(ax.collections for ax in fig.axes)


@pytest.mark.slow
def test_drawing_and_picture_call_out_the_floor_radius():
    from designer.outputs import drawing

    texts = drawing_texts("rect_pockets")
    assert "FLOOR EDGES R0.2 (BULL-NOSE)" in texts       # the slot callout names the tool's corner radius
    assert "R0.2 TYP" in texts.splitlines()               # on the floor radius in section A-A
    # the tool, from the catalogue (materials/tools.yaml): the largest metric end mill with R0.2
    # that is at most 60 % of the slot and leaves the gauge backing on the flat floor
    beam = cad.resolve(record("rect_pockets"))
    assert f"in R0.2, the corner radius of the end mill Ø{beam.end_mill * 1e3:g} R0.2 mm" in texts
    flats = drawing_texts("round_flats")
    assert "ENDS R0.2 (BULL-NOSE, END MILL Ø" in flats and "R0.2 TYP" in flats.splitlines()
    beam = cad.resolve(record("round_flats"))
    meshes = cad.model_meshes(beam, cad.build_solid(beam))
    fig = drawing.plot_model(meshes, beam)
    titles = [ax.get_title() for ax in fig.axes]
    assert any(t.startswith("R0.2 floor radius at the flat's end") for t in titles), titles
    # the close-up is cut through the middle (Y <= 0) around the first flat's clamp-side end
    v = meshes["corner"]["vertices"]
    assert v[:, 1].max() == pytest.approx(0.0, abs=1e-6)
    assert v[:, 0].min() < (0.015 - 0.0089 / 2) / MM < v[:, 0].max()


@pytest.mark.parametrize("name", ["prototype-b", "gripper-finger-left-hand-prototype-rev-c-for-the-conveyor-line-4",
                                  "x" * 300])
def test_the_design_s_name_stays_inside_the_title_block(name):
    # measured on the rendered text (matplotlib's own extent), against the block's right edge
    from designer.outputs import drawing
    from designer.outputs.drawing import sheet

    rec = record("prototype_b")
    rec["spec"]["name"] = name
    fig = drawing.plot_drawing(cad.resolve(rec))
    ax = fig.axes[0]
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    renderer = FigureCanvasAgg(fig).get_renderer()
    title = next(t for t in ax.texts if t.get_fontweight() == "bold" and t.get_fontsize() >= sheet.MIN_TITLE_PT
                 and (t.get_text() == name or t.get_text().endswith("…")))
    right = ax.transData.inverted().transform(title.get_window_extent(renderer))[1, 0]
    assert right <= sheet.PAPER[0] - sheet.BORDER - 1.0
    assert title.get_text() == name or len(name) > 100   # cut only when even the smallest size is too wide


def test_the_tolerance_note_says_every_limit_holds_only_where_the_record_says_so():
    """The drawing's note 2 said 'every limit holds at their extremes' of any design checked at
    tolerance corners, also of one whose corners break limits (its title block saying
    INFEASIBLE): the note now follows design.json's tolerances.constraints."""
    from designer.outputs import drawing

    r = record("rect_pockets")
    held = {"name": "stress_feature", "satisfied": True}
    for rows, said in [([held], "2. Tolerances ISO 2768-m: every limit holds at their extremes. Break sharp edges "
                                "0.2 max."),
                       ([held, {"name": "fatigue_feature", "satisfied": False}],
                        "2. Tolerances ISO 2768-m: some limits break at their extremes (report.md). Break sharp "
                        "edges 0.2 max.")]:
        r["tolerances"] = {"label": "ISO 2768-m", "constraints": rows}
        fig = drawing.plot_drawing(cad.resolve(r))
        assert said in [t.get_text() for t in fig.axes[0].texts]


@pytest.mark.parametrize("count, spacing", [(3, 0.02), (18, 0.0035), (60, 0.001)])
def test_every_groove_s_position_is_written_above_the_notes(count, spacing):
    """Each load groove's position from the clamp face is on the drawing, all of it above the
    band of notes and the title block (66 mm from the sheet's bottom edge). Each groove on a
    dimension line of its own, 18 grooves 3.5 mm apart had run down over the notes and off the
    sheet; past six they are ordinates, their figures in as many rows as they need not to touch
    (measured on the rendered text)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    from designer.outputs import drawing
    from designer.outputs.part import fmt_mm

    rec = record("rect_pockets")
    positions = [0.082 + spacing * i for i in range(count)]
    rec["spec"]["cad"]["groove_positions"] = positions
    fig = drawing.plot_drawing(cad.resolve(rec))
    ax = fig.axes[0]
    renderer = FigureCanvasAgg(fig).get_renderer()
    boxes = {}
    for t in ax.texts:
        box = ax.transData.inverted().transform(t.get_window_extent(renderer))
        boxes.setdefault(t.get_text(), []).append(box)
    for x in positions:
        figure = fmt_mm(x)
        assert figure in boxes, figure
        assert min(b[:, 1].min() for b in boxes[figure]) > 66.0
    if count > 6:    # the ordinates' figures do not overlap one another
        figures = [min(boxes[fmt_mm(x)], key=lambda b: b[:, 1].min()) for x in positions]
        for i, a in enumerate(figures):
            for b in figures[i + 1:]:
                apart = (a[1, 0] <= b[0, 0] + 0.05 or b[1, 0] <= a[0, 0] + 0.05 or a[1, 1] <= b[0, 1] + 0.05
                         or b[1, 1] <= a[0, 1] + 0.05)
                assert apart, (a, b)
