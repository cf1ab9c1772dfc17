"""Tests of iceenvs.rendering: floe and thickness-distribution pictures, annotation panels,
and the window."""
import math
import sys

import numpy as np
import pytest
from gymnasium.error import DependencyNotInstalled

pygame = pytest.importorskip("pygame")

from iceenvs.rendering import (
    ARROW_CIRCLE, ARROW_COLOURS, BACKGROUND, CHAIN, CLUSTER_LEGEND, CLUSTER_PALETTE, FROZEN,
    ITD_BACKGROUND, ITD_TARGET, LARGEST_CLUSTER, PANEL_BACKGROUND, SINGLE_FLOE, SPEED_SCALE,
    Window, annotate, draw_floes, draw_itd, season,
)

VIRIDIS_TOP = (253, 231, 37)
VIRIDIS_BOTTOM = (68, 1, 84)


def one_floe(x, y, r=10.0, box=(100.0, 100.0), size=200, **kw):
    return draw_floes(np.array([[x, y]]), np.array([r]), box, np.array([0.5]), size=size, **kw)


def painted(frame, background=BACKGROUND):
    return np.any(frame != np.array(background, dtype=np.uint8), axis=-1)


def test_frame_shape_and_dtype_for_rectangular_box():
    frame = draw_floes(np.array([[10.0, 10.0]]), np.array([2.0]), (120.0, 50.0),
                       np.array([0.0]), size=300)
    assert frame.dtype == np.uint8
    assert frame.shape == (round(300 * 50 / 120), 300, 3)


def test_single_floe_centre_painted_corner_background_and_area():
    frame = one_floe(50.0, 50.0)
    mask = painted(frame)
    assert mask[100, 100]
    assert not mask[0, 0]
    assert abs(mask.sum() - math.pi * 20**2) < 0.1 * math.pi * 20**2


def test_y_points_up():
    mask = painted(one_floe(50.0, 80.0))
    rows = np.nonzero(mask.any(axis=1))[0]
    assert rows.size > 0
    assert rows.max() < 100            # all painted rows in the upper half
    assert abs(rows.mean() - 40) < 2   # centre at y = 80 m → row 200 - 160


def test_periodic_image_across_the_left_edge():
    mask = painted(one_floe(1.0, 50.0, r=5.0))
    assert mask[:, -1].any()
    assert mask[:, 0].any()


def test_periodic_images_in_a_corner():
    mask = painted(one_floe(2.0, 2.0, r=5.0))
    for row, col in ((-1, 0), (-1, -1), (0, 0), (0, -1)):
        assert mask[row, col]


def test_speed_colours_differ_and_frozen_is_grey():
    pos = np.array([[25.0, 50.0], [75.0, 50.0]])
    frame = draw_floes(pos, np.array([10.0, 10.0]), (100.0, 100.0), np.array([0.0, 1.0]),
                       size=200)
    assert not np.array_equal(frame[100, 50], frame[100, 150])
    frozen = draw_floes(pos, np.array([10.0, 10.0]), (100.0, 100.0), np.array([0.0, 1.0]),
                        frozen=np.array([False, True]), size=200)
    r, g, b = frozen[100, 150].astype(int)
    assert max(r, g, b) - min(r, g, b) <= 2
    assert not np.array_equal(frozen[100, 50], frozen[100, 150])


def test_speed_scale_saturates_colours():
    pos = np.array([[25.0, 50.0], [75.0, 50.0]])
    frame = draw_floes(pos, np.array([10.0, 10.0]), (100.0, 100.0), np.array([2.0, 5.0]),
                       speed_scale=1.0, size=200)
    assert np.array_equal(frame[100, 50], frame[100, 150])


def chain_frame(force):
    """Touching pairs (0, 1) around y = 50 m with `force` and (2, 3) around y = 20 m with 1 kN."""
    pos = np.array([[40.0, 50.0], [60.0, 50.0], [40.0, 20.0], [60.0, 20.0]])
    return draw_floes(pos, np.full(4, 10.0), (100.0, 100.0), np.full(4, 0.2),
                      contact_i=np.array([0, 2]), contact_j=np.array([1, 3]),
                      contact_force=np.array([force, 1e3]), size=200)


def test_force_chain_drawn_between_centres():
    is_chain = np.all(chain_frame(1e3) == np.array(CHAIN, dtype=np.uint8), axis=-1)
    assert is_chain[95:106, 85:116].sum() > 20
    assert not is_chain[:80].any()


def test_zero_force_draws_no_chain():
    is_chain = np.all(chain_frame(0.0) == np.array(CHAIN, dtype=np.uint8), axis=-1)
    assert not is_chain[:130].any()       # nothing around the zero-force pair
    assert is_chain[130:].any()           # the loaded pair still has its chain


def test_force_chain_width_grows_with_force():
    is_chain = np.all(chain_frame(1e2) == np.array(CHAIN, dtype=np.uint8), axis=-1)
    weak, strong = is_chain[:130, 100].sum(), is_chain[130:, 100].sum()
    assert 1 <= weak < strong


def test_force_chain_uses_minimum_image():
    pos = np.array([[3.0, 50.0], [97.0, 50.0]])
    frame = draw_floes(pos, np.array([3.0, 3.0]), (100.0, 100.0), np.array([0.2, 0.2]),
                       contact_i=np.array([0]), contact_j=np.array([1]),
                       contact_force=np.array([1.0]), size=200)
    is_chain = np.all(frame == np.array(CHAIN, dtype=np.uint8), axis=-1)
    assert is_chain.any()
    assert not is_chain[:, 20:180].any()   # no segment across the middle of the box


def test_itd_shape_and_taller_bar_for_larger_fraction():
    h = np.array([0.0, 0.5, 1.0, 2.0])
    g = np.array([0.1, 0.6, 0.2, 0.1])
    frame = draw_itd(h, g, size=600)
    assert frame.dtype == np.uint8
    assert frame.shape == (360, 600, 3)
    mask = painted(frame, ITD_BACKGROUND)
    share = 600 // 4
    middle = [mask[:, c * share + share // 3: c * share + 2 * share // 3].sum() for c in range(4)]
    assert middle[1] > 2 * middle[2]


def test_itd_target_is_drawn():
    h = np.array([0.0, 0.5, 1.0])
    g = np.array([0.2, 0.5, 0.3])
    target_colour = np.array(ITD_TARGET, dtype=np.uint8)
    without = draw_itd(h, g, size=300)
    with_target = draw_itd(h, g, target=np.array([0.1, 0.3, 0.6]), size=300)
    assert not np.all(without == target_colour, axis=-1).any()
    assert np.all(with_target == target_colour, axis=-1).any()


@pytest.mark.parametrize("kwargs, name", [
    (dict(radii=np.array([1.0, 1.0, 1.0])), "radii"),
    (dict(speeds=np.array([0.0])), "speeds"),
    (dict(positions=np.array([[1.0, np.nan], [5.0, 5.0]])), "positions"),
    (dict(radii=np.array([1.0, -1.0])), "radii"),
    (dict(box_size=(10.0, 0.0)), "box_size"),
    (dict(frozen=np.array([True])), "frozen"),
    (dict(contact_i=np.array([0]), contact_j=np.array([1]), contact_force=np.array([1.0, 2.0])),
     "contact_force"),
    (dict(contact_i=np.array([0]), contact_j=np.array([2]), contact_force=np.array([1.0])),
     "contact_j"),
])
def test_draw_floes_rejects_bad_input(kwargs, name):
    args = dict(positions=np.array([[1.0, 1.0], [5.0, 5.0]]), radii=np.array([1.0, 1.0]),
                box_size=(10.0, 10.0), speeds=np.array([0.0, 1.0]))
    args.update(kwargs)
    with pytest.raises(ValueError, match=name):
        draw_floes(**args)


@pytest.mark.parametrize("h, g, name", [
    ([0.0, 1.0], [1.0], "g"),
    ([0.0, np.nan], [0.5, 0.5], "h"),
    ([0.0, 1.0], [1.5, -0.5], "g"),
])
def test_draw_itd_rejects_bad_input(h, g, name):
    with pytest.raises(ValueError, match=name):
        draw_itd(np.array(h), np.array(g))


# -- fixed speed scale -------------------------------------------------------------------
def two_floes(speeds, **kw):
    pos = np.array([[25.0, 50.0], [75.0, 50.0]])
    return draw_floes(pos, np.array([10.0, 10.0]), (100.0, 100.0), np.asarray(speeds, float),
                      size=200, **kw)


def test_same_speed_same_colour_whatever_the_fastest_floe():
    assert SPEED_SCALE == 0.5
    slow_max, fast_max = two_floes([0.2, 0.3]), two_floes([0.2, 0.5])
    assert np.array_equal(slow_max[100, 50], fast_max[100, 50])
    assert not np.array_equal(slow_max[100, 150], fast_max[100, 150])
    assert np.array_equal(two_floes([0.2, 0.3], speed_scale=None)[100, 50], slow_max[100, 50])


def test_speed_above_the_scale_saturates_to_the_top_colour():
    frame = two_floes([0.0, 2.0])
    assert tuple(frame[100, 150]) == VIRIDIS_TOP
    assert tuple(frame[100, 50]) == VIRIDIS_BOTTOM
    assert tuple(two_floes([0.0, 0.5])[100, 150]) == VIRIDIS_TOP
    assert tuple(two_floes([0.0, 0.4])[100, 150]) != VIRIDIS_TOP


# -- cluster colouring ---------------------------------------------------------------------
CLUSTER_POS = np.array([[15.0, 80.0], [35.0, 80.0],                 # label 3: 2 big floes
                        [15.0, 40.0], [30.0, 40.0], [45.0, 40.0],   # label 8: 3 small floes
                        [80.0, 80.0],                               # label 1: alone, biggest
                        [80.0, 30.0]])                              # label 4: alone, frozen


def cluster_frame(labels, frozen=None):
    radii = np.array([10.0, 10.0, 6.0, 6.0, 6.0, 14.0, 8.0])
    return draw_floes(CLUSTER_POS, radii, (100.0, 100.0), np.zeros(7), labels=labels,
                      frozen=frozen, size=200)


def centre_colours(frame):
    return [tuple(int(v) for v in frame[200 - round(2 * y), round(2 * x)]) for x, y in CLUSTER_POS]


def test_labels_colour_floes_by_cluster():
    frozen = np.array([False] * 6 + [True])
    c = centre_colours(cluster_frame(np.array([3, 3, 8, 8, 8, 1, 4]), frozen))
    assert c[0] == c[1] == LARGEST_CLUSTER            # largest by area, not by floe count
    assert c[2] == c[3] == c[4] == CLUSTER_PALETTE[8 % len(CLUSTER_PALETTE)]
    assert c[5] == SINGLE_FLOE                        # a lone floe is not a cluster
    assert c[6] == FROZEN


def test_largest_cluster_by_total_area():
    c = centre_colours(cluster_frame(np.array([1, 1, 0, 0, 0, 11, 10])))
    assert c[0] == c[1] == LARGEST_CLUSTER            # 2 r² = 200 m² against 3 r² = 108 m²
    assert c[2] == c[3] == c[4] == CLUSTER_PALETTE[0]
    c = centre_colours(cluster_frame(np.array([0, 1, 2, 2, 2, 5, 6])))
    assert c[2] == c[3] == c[4] == LARGEST_CLUSTER    # the only cluster of several floes
    assert c[0] == c[1] == c[5] == SINGLE_FLOE


def test_only_single_floes_have_no_highlight():
    frame = cluster_frame(np.arange(7))
    assert not np.all(frame == np.array(LARGEST_CLUSTER, dtype=np.uint8), axis=-1).any()
    assert set(centre_colours(frame)) == {SINGLE_FLOE}


@pytest.mark.parametrize("labels", [np.zeros(6, dtype=int), np.zeros((7, 1), dtype=int),
                                    np.zeros(7), np.array(["a"] * 7)])
def test_bad_labels_raise(labels):
    with pytest.raises(ValueError, match="labels"):
        cluster_frame(labels)


# -- annotate ------------------------------------------------------------------------------
def panel_of(frame, picture):
    return frame[:, picture.shape[1]:]


def is_colour(a, colour):
    return np.all(a == np.array(colour, dtype=np.uint8), axis=-1)


def test_annotate_keeps_the_picture_and_adds_a_panel():
    pic = one_floe(50.0, 50.0, size=600)
    frame = annotate(pic, text=["t = 300 s", "A = 0.812"], colour_bar=("speed [m/s]", 0, 0.5),
                     arrow=(0.3, 0.4), arrow_label="wind 10 m/s")
    assert frame.dtype == np.uint8
    assert frame.shape == (600, 600 + 180, 3)          # 0.3 x width
    assert np.array_equal(frame[:, :600], pic)
    assert annotate(one_floe(50.0, 50.0), text="x").shape[1] == 200 + 150   # minimum width
    assert annotate(pic, text="x", panel_width=222).shape == (600, 822, 3)


def test_annotate_pads_a_short_picture_with_the_panel_background():
    pic = one_floe(50.0, 50.0, size=40)
    frame = annotate(pic, text=["a", "b"], colour_bar=("v", 0, 1), legend=CLUSTER_LEGEND,
                     arrow=(1, 0))
    assert frame.shape[0] > 40
    assert np.array_equal(frame[:40, :40], pic)
    assert is_colour(frame[40:, :40], PANEL_BACKGROUND).all()


def test_annotate_draws_the_colour_bar_top_high_bottom_low():
    pic = one_floe(50.0, 50.0, size=300)
    without = panel_of(annotate(pic, text="t = 0 s"), pic)
    assert not is_colour(without, VIRIDIS_TOP).any()
    panel = panel_of(annotate(pic, colour_bar=("speed [m/s]", 0.0, 0.5)), pic)
    top_rows = np.nonzero(is_colour(panel, VIRIDIS_TOP).any(axis=1))[0]
    bottom_rows = np.nonzero(is_colour(panel, VIRIDIS_BOTTOM).any(axis=1))[0]
    assert top_rows.size and bottom_rows.size
    assert top_rows.max() < bottom_rows.min() - 50     # a tall bar, high values at the top
    assert is_colour(panel, VIRIDIS_TOP).sum() >= 12   # a bar, not a stray pixel


def arrow_geometry(frame, picture, colour=ARROW_COLOURS[0]):
    """(centre x, centre y, radius) of the arrow circle and the arrow-coloured pixels."""
    panel = panel_of(frame, picture)
    rows, cols = np.nonzero(is_colour(panel, ARROW_CIRCLE))
    cx, cy = (cols.min() + cols.max()) / 2, (rows.min() + rows.max()) / 2
    radius = (cols.max() - cols.min()) / 2
    ar, ac = np.nonzero(is_colour(panel, colour))
    return cx, cy, radius, ar, ac


def test_arrow_points_plus_x():
    pic = one_floe(50.0, 50.0, size=300)
    cx, cy, radius, rows, cols = arrow_geometry(annotate(pic, arrow=(1.0, 0.0)), pic)
    assert radius > 10
    assert (cols > cx + 0.7 * radius).any()
    assert not (cols < cx - 3).any()
    assert np.all(np.abs(rows - cy) < 0.4 * radius)


def test_arrow_y_points_up_and_long_arrows_are_clipped():
    pic = one_floe(50.0, 50.0, size=300)
    cx, cy, radius, rows, cols = arrow_geometry(annotate(pic, arrow=(0.0, 0.5)), pic)
    assert (rows < cy - 0.3 * radius).any()
    assert not (rows < cy - 0.6 * radius).any()       # half the full length
    assert not (rows > cy + 3).any()
    assert np.array_equal(annotate(pic, arrow=(0.0, 7.0)), annotate(pic, arrow=(0.0, 1.0)))


def test_two_arrows_with_their_colours_and_labels():
    pic = one_floe(50.0, 50.0, size=300)
    frame = annotate(pic, arrow=[((1.0, 0.0), "wind 20 m/s"), ((0.0, -1.0), None, (255, 0, 0))])
    cx, cy, radius, rows, cols = arrow_geometry(frame, pic)
    assert (cols > cx + 0.7 * radius).any()            # first: white, +x
    _, _, _, red_rows, red_cols = arrow_geometry(frame, pic, (255, 0, 0))
    assert (red_rows > cy + 0.7 * radius).any()        # second: red, -y (down on screen)
    assert not (red_rows < cy - 3).any()
    labelled = panel_of(frame, pic)[int(cy + radius) + 3:]
    assert (labelled.astype(int).sum(axis=-1) > 3 * 200).any()   # white label under the circle


def test_legend_swatches_are_drawn():
    pic = one_floe(50.0, 50.0, size=300)
    panel = panel_of(annotate(pic, legend=[((255, 0, 0), "a"), ((0, 255, 0), "b")]), pic)
    red, green = is_colour(panel, (255, 0, 0)), is_colour(panel, (0, 255, 0))
    assert red.sum() > 20 and green.sum() > 20
    assert np.nonzero(red)[0].mean() < np.nonzero(green)[0].mean()   # in order, top to bottom


def test_text_is_written_and_skipped_without_fonts(monkeypatch):
    pic = one_floe(50.0, 50.0, size=300)
    panel = panel_of(annotate(pic, text=["t = 300 s", "A = 0.81"]), pic)
    assert (~is_colour(panel, PANEL_BACKGROUND)).sum() > 50

    def no_font(*args, **kwargs):
        raise pygame.error("no fonts")

    monkeypatch.setattr(pygame.font, "Font", no_font)
    panel = panel_of(annotate(pic, text=["t = 300 s"], colour_bar=("v [m/s]", 0, 1)), pic)
    assert is_colour(panel, VIRIDIS_TOP).any()        # the bar is still drawn
    assert is_colour(panel[:40], PANEL_BACKGROUND).all()   # the text line is blank


@pytest.mark.parametrize("kwargs, name", [
    (dict(picture=np.zeros((10, 10, 3))), "picture"),
    (dict(picture=np.zeros((10, 10), dtype=np.uint8)), "picture"),
    (dict(colour_bar=("v", 1.0, 1.0)), "colour_bar"),
    (dict(colour_bar=("v", 0.0, np.nan)), "colour_bar"),
    (dict(colour_bar=(0.0, 1.0)), "colour_bar"),
    (dict(arrow=(1.0, 0.0, 0.0)), "arrow"),
    (dict(arrow=(np.nan, 0.0)), "arrow"),
    (dict(arrow=[((1, 0), "a"), ((0, 1), "b"), ((1, 1), "c")]), "arrow"),
    (dict(arrow=[((1, 0), "a", (300, 0, 0))]), "arrow colour"),
    (dict(arrow=[((1, 0), "a")], arrow_label="b"), "arrow_label"),
    (dict(arrow_label="wind"), "arrow_label"),
    (dict(legend=[((300, 0, 0), "a")]), "legend"),
    (dict(legend=[((255, 0, 0),)]), "legend"),
    (dict(text=[1, 2]), "text"),
    (dict(panel_width=0), "panel_width"),
])
def test_annotate_rejects_bad_input(kwargs, name):
    args = dict(picture=np.zeros((10, 10, 3), dtype=np.uint8))
    args.update(kwargs)
    picture = args.pop("picture")
    with pytest.raises(ValueError, match=name):
        annotate(picture, **args)


# -- ITD labels ----------------------------------------------------------------------------
ITD_H = np.array([0.0, 0.5, 1.0, 2.0])
ITD_G = np.array([0.1, 0.6, 0.2, 0.1])


def test_itd_title_with_day_and_axis_labels():
    plain = draw_itd(ITD_H, ITD_G)
    titled = draw_itd(ITD_H, ITD_G, day=123)
    assert titled.shape == plain.shape == (360, 600, 3)
    title_area = (slice(0, 28), slice(60, 600))
    assert not painted(plain[title_area], ITD_BACKGROUND).any()
    assert painted(titled[title_area], ITD_BACKGROUND).sum() > 50
    assert painted(plain[:, :48], ITD_BACKGROUND)[61:300].sum() > 30   # y-tick values
    assert painted(plain[335:], ITD_BACKGROUND).sum() > 50              # x-axis label
    assert np.array_equal(titled[40:], plain[40:])                      # only the title differs


def test_itd_legend_shows_the_target_line_above_the_plot():
    frame = draw_itd(ITD_H, ITD_G, target=np.array([0.2, 0.3, 0.3, 0.2]), day=10)
    above = frame[:61, 300:]
    assert np.all(above == np.array(ITD_TARGET, dtype=np.uint8), axis=-1).sum() > 10


def test_itd_without_fonts_still_draws_the_bars(monkeypatch):
    def no_font(*args, **kwargs):
        raise pygame.error("no fonts")

    monkeypatch.setattr(pygame.font, "Font", no_font)
    frame = draw_itd(ITD_H, ITD_G, day=123)
    assert frame.shape == (360, 600, 3)
    assert not painted(frame[:28], ITD_BACKGROUND).any()
    assert painted(frame[100:290, 210:250], ITD_BACKGROUND).all()      # the tallest bar


@pytest.mark.parametrize("day, name", [(0, "winter"), (44, "winter"), (45, "spring"),
                                       (180, "summer"), (270, "autumn"), (-10, "winter"),
                                       (359.5, "winter"), (400, "winter"),
                                       (3 * 360 + 100, "spring")])
def test_season(day, name):
    assert season(day) == name


def test_itd_rejects_a_bad_day():
    with pytest.raises(ValueError, match="day"):
        draw_itd(ITD_H, ITD_G, day=float("nan"))


def test_missing_pygame_raises_dependency_not_installed(monkeypatch):
    monkeypatch.setitem(sys.modules, "pygame", None)
    with pytest.raises(DependencyNotInstalled, match="seaice-gym\\[render\\]"):
        one_floe(50.0, 50.0)


def test_window_shows_a_frame_and_closes_twice(monkeypatch):
    monkeypatch.setenv("SDL_VIDEODRIVER", "dummy")
    monkeypatch.setenv("SDL_AUDIODRIVER", "dummy")
    frame = one_floe(50.0, 50.0, size=64)
    window = Window("test", frame.shape[1], frame.shape[0], fps=1000)
    try:
        window.show(frame)
        assert window.screen.get_size() == (64, 64)
        shown = np.transpose(pygame.surfarray.array3d(window.screen), (1, 0, 2))
        assert np.array_equal(shown, frame)
    finally:
        window.close()
    window.close()
    assert window.screen is None


# -- the view of a channel: draw_view, thickness_colours, annotate(side="bottom") ------------
from iceenvs.rendering import (  # noqa: E402
    HULL, LEAD, OUTSIDE, THICKNESS_COLOURS, ViewBox, draw_view, thickness_colours, view_box,
    view_window,
)
from physics.ice_fields import Lead  # noqa: E402


def test_view_box_keeps_one_scale_and_maps_y_up():
    box = view_box((-50.0, 350.0, 0.0, 200.0), max_width=800, max_height=600)
    assert box.scale == pytest.approx(2.0)
    assert (box.width, box.height) == (800, 400)
    tall = view_box((0.0, 100.0, 0.0, 400.0), max_width=800, max_height=600)
    assert tall.height == 600 and tall.width == 150          # the height limits the scale
    (c0, r0), (c1, r1) = box.pixels([(-50.0, 200.0), (350.0, 0.0)])
    assert (c0, r0) == (box.left, box.top)
    assert (c1, r1) == (box.left + 800, box.top + 400)


def test_a_floe_is_a_disc_at_its_true_size_and_clipped_at_the_window():
    box = view_box((0.0, 100.0, 0.0, 50.0), max_width=400)              # 4 px/m
    picture = draw_view(box, [[50.0, 25.0], [0.0, 25.0]], [5.0, 5.0], (100.0, 50.0),
                        periodic=(True, True))
    assert picture.shape == (box.picture_size[1], box.picture_size[0], 3)
    plot = picture[box.plot]
    ice = is_colour(plot, THICKNESS_COLOURS[0])
    middle = ice[:, 100:300].sum()
    assert abs(middle - math.pi * 20 ** 2) < 0.1 * math.pi * 20 ** 2    # r = 5 m = 20 px
    # the floe at x = 0 shows its halves at both ends (periodic), none in the margins
    assert ice[:, :30].sum() > 300 and ice[:, -30:].sum() > 300
    margins = picture.copy()
    margins[box.plot] = 0
    assert not is_colour(margins, THICKNESS_COLOURS[0]).any()


def test_walls_shade_what_lies_beyond_them():
    box = view_box((-50.0, 150.0, 0.0, 50.0), max_width=400)            # 2 px/m
    plot = draw_view(box, np.zeros((0, 2)), np.zeros(0), (500.0, 50.0))[box.plot]
    outside = is_colour(plot, OUTSIDE)
    assert outside[:, :95].mean() > 0.95                                 # x < 0
    assert not outside[:, 105:].any()


def test_a_lead_is_shaded_within_the_band_and_wraps_across_a_periodic_y():
    box = view_box((0.0, 400.0, 0.0, 200.0), max_width=800)             # 2 px/m
    lead = Lead(200.0, 190.0, 0.25 * math.pi, 20.0, 200.0)
    picture = draw_view(box, np.zeros((0, 2)), np.zeros(0), (400.0, 200.0),
                        periodic=(False, True), leads=(lead,), ice_band=(100.0, 300.0))
    shaded = is_colour(picture[box.plot], LEAD)
    (c, r), = box.pixels([(200.0, 190.0)]).astype(int) - (box.left, box.top)
    assert shaded[r - 3:r + 4, c - 3:c + 4].all()                        # on the centre line
    (c, r), = box.pixels([(230.0, 20.0)]).astype(int) - (box.left, box.top)
    assert shaded[r - 3:r + 4, c - 3:c + 4].all()                        # its image below y = 0
    assert not shaded[:, :195].any() and not shaded[:, 605:].any()      # only in the band
    no_lead = draw_view(box, np.zeros((0, 2)), np.zeros(0), (400.0, 200.0))
    assert not is_colour(no_lead, LEAD).any()


def test_hull_and_axes_are_drawn():
    box = view_box((0.0, 200.0, 0.0, 100.0), max_width=400)
    hull = np.array([[90.0, 45.0], [110.0, 45.0], [110.0, 55.0], [90.0, 55.0]])
    picture = draw_view(box, np.zeros((0, 2)), np.zeros(0), (200.0, 100.0), hull_vertices=hull)
    rows, cols = np.nonzero(is_colour(picture, HULL))
    assert abs(cols.mean() - box.pixels([(100.0, 50.0)])[0, 0]) < 1.5
    assert abs(rows.mean() - box.pixels([(100.0, 50.0)])[0, 1]) < 1.5
    below = picture[box.top + box.height + 2:]                          # tick labels under the plot
    assert (~is_colour(below, PANEL_BACKGROUND)).sum() > 100


def test_thickness_colours_by_class_with_a_legend_of_the_classes_present():
    colours, legend = thickness_colours([1.2, 3.0, 1.2], classes=(1.2, 3.0))
    assert [tuple(c) for c in colours] == [THICKNESS_COLOURS[0], THICKNESS_COLOURS[1],
                                           THICKNESS_COLOURS[0]]
    assert [text for _, text in legend] == ["ice 1.2 m thick", "ice 3.0 m thick"]
    colours, legend = thickness_colours([3.0, 3.0], classes=(1.2, 3.0))
    assert {tuple(c) for c in colours} == {THICKNESS_COLOURS[1]}       # the thick class alone
    assert len(legend) == 1 and "3.0 m" in legend[0][1]
    colours, legend = thickness_colours([1.0, 1.0])
    assert {tuple(c) for c in colours} == {THICKNESS_COLOURS[0]} and len(legend) == 1


@pytest.mark.parametrize("call, name", [
    (lambda: view_window("side", (100.0, 50.0), 10.0), "follow"),
    (lambda: view_window("follow", (100.0, 50.0), 10.0, behind=-1.0), "behind"),
    (lambda: view_box((0.0, 0.0, 0.0, 1.0)), "window"),
    (lambda: ViewBox(0.0, 1.0, 0.0, 1.0, -2.0), "scale"),
    (lambda: draw_view("box", np.zeros((0, 2)), np.zeros(0), (1.0, 1.0)), "ViewBox"),
    (lambda: draw_view(view_box((0.0, 1.0, 0.0, 1.0)), [[0.5, 0.5]], [0.1], (1.0, 1.0),
                       floe_colours=np.zeros((2, 3), dtype=np.uint8)), "floe_colours"),
    (lambda: draw_view(view_box((0.0, 1.0, 0.0, 1.0)), np.zeros((0, 2)), np.zeros(0),
                       (1.0, 1.0), ice_band=(2.0, 1.0)), "ice_band"),
    (lambda: draw_view(view_box((0.0, 1.0, 0.0, 1.0)), np.zeros((0, 2)), np.zeros(0),
                       (1.0, 1.0), leads=[(1.0, 2.0)]), "lead 0"),
    (lambda: draw_view(view_box((0.0, 1.0, 0.0, 1.0)), np.zeros((0, 2)), np.zeros(0),
                       (1.0, 1.0), leads=[Lead(0.5, 0.5, 0.0, -1.0)]), "positive width"),
    (lambda: thickness_colours([1.0], classes=(-1.0,)), "classes"),
    (lambda: annotate(np.zeros((4, 4, 3), dtype=np.uint8), side="left"), "side"),
    (lambda: annotate(np.zeros((4, 4, 3), dtype=np.uint8), legend=[((1, 2, 3), "a", "star")]),
     "kind"),
])
def test_view_functions_reject_bad_input(call, name):
    with pytest.raises(ValueError, match=name):
        call()


def test_annotate_bottom_puts_a_strip_under_the_picture():
    pic = one_floe(50.0, 50.0, size=600)
    frame = annotate(pic, text=["t = 0 s", "A = 0.5"], arrow=(1.0, 0.0), side="bottom",
                     legend=[((255, 0, 0), "a", "line"), ((0, 255, 0), "b", "band")])
    assert frame.shape[1] == 600 and frame.shape[0] > 600
    assert np.array_equal(frame[:600], pic)
    strip = frame[600:]
    assert is_colour(strip, (255, 0, 0)).sum() > 10 and is_colour(strip, (0, 255, 0)).sum() > 10
    assert is_colour(strip, ARROW_CIRCLE).any()


# -- ShipNavigation-v1's frames ------------------------------------------------------------
V1 = "iceenvs/ShipNavigation-v1"


def v1_env(**kwargs):
    import gymnasium as gym

    import iceenvs  # noqa: F401
    from iceenvs.facts import env_facts

    return gym.make(V1, render_mode="rgb_array", **{**env_facts(V1).small, **kwargs})


def hull_column(frame, box):
    rows, cols = np.nonzero(is_colour(frame[box.plot], HULL))
    assert cols.size > 100
    return cols.mean()


def test_follow_view_keeps_the_ship_in_place_and_moves_the_ice():
    env = v1_env(leads=0)
    try:
        env.reset(seed=1)
        u = env.unwrapped
        box0 = u.view_box()
        first, x0 = env.render(), float(u.sim.ship.position[0])
        for _ in range(5):
            env.step(np.zeros(1))
        box1 = u.view_box()
        second, x1 = env.render(), float(u.sim.ship.position[0])
    finally:
        env.close()
    assert first.shape == second.shape
    assert x1 - x0 > 15.0                                  # the ship sailed 20 m ...
    assert abs(hull_column(first, box0) - hull_column(second, box1)) < 3.0   # ... in place
    # the ice moved left by the distance sailed
    shift = int(round((x1 - x0) * box0.scale))
    ice0 = is_colour(first[box0.plot], THICKNESS_COLOURS[0])
    ice1 = is_colour(second[box1.plot], THICKNESS_COLOURS[0])
    assert ice0.sum() > 1000

    def overlap(a, b):
        return (a & b).sum() / max(1, min(a.sum(), b.sum()))

    assert overlap(ice0[:, shift:], ice1[:, :-shift]) > 0.9
    assert overlap(ice0, ice1) < 0.8


def test_v1_frame_shades_its_leads():
    env = v1_env(leads=2)
    try:
        env.reset(seed=2)
        u = env.unwrapped
        u.view = "overview"                                    # every lead in the window
        frame, box = env.render(), u.view_box()
        leads = u.leads
    finally:
        env.close()
    shaded = is_colour(frame[box.plot], LEAD)
    assert len(leads) == 2 and shaded.sum() > 500
    for lead in leads:
        (c, r), = box.pixels([(lead.x, lead.y)]).astype(int) - (box.left, box.top)
        assert shaded[max(r - 2, 0):r + 3, max(c - 2, 0):c + 3].mean() > 0.5
    env = v1_env(leads=0, view="overview")
    try:
        env.reset(seed=2)
        assert not is_colour(env.render(), LEAD).any()
    finally:
        env.close()


@pytest.mark.parametrize("fraction", [0.0, 1.0])
def test_v1_frame_colours_the_thick_class(fraction):
    env = v1_env(thick_fraction=fraction)
    try:
        env.reset(seed=3)
        frame, box = env.render(), env.unwrapped.view_box()
    finally:
        env.close()
    thick = is_colour(frame, THICKNESS_COLOURS[1])
    thin = is_colour(frame[box.plot], THICKNESS_COLOURS[0])
    if fraction:
        assert thick[box.plot].sum() > 500 and not thin.any()
    else:
        assert thin.sum() > 500 and not thick.any()


def test_v1_overview_fills_the_frame_with_the_channel():
    env = v1_env(view="overview")
    try:
        env.reset(seed=4)
        u = env.unwrapped
        frame, box = env.render(), u.view_box()
        x, y = (float(v) for v in u.sim.ship.position)
        length, width = u.sim.box.lx, u.sim.box.ly
        u.view = "follow"
        follow = env.render()
    finally:
        env.close()
    assert (box.x0, box.x1, box.y0, box.y1) == (0.0, length, 0.0, width)
    assert box.width / box.height == pytest.approx(length / width, rel=0.02)
    assert box.width >= 0.85 * frame.shape[1] and frame.shape[1] > frame.shape[0]
    c, r = box.pixels([(x, y)])[0]
    assert abs(hull_column(frame, box) + box.left - c) < 3.0   # the ship where it is
    assert follow.shape != frame.shape


@pytest.mark.parametrize("kwargs, name", [
    (dict(view="side"), "follow"), (dict(view=3), "view"), (dict(view_behind=-5.0), "view_behind"),
    (dict(view_ahead=float("nan")), "view_ahead"),
    (dict(view_behind=0.0, view_ahead=0.0), "view_ahead"),
])
def test_v1_bad_view_arguments_raise(kwargs, name):
    with pytest.raises(ValueError, match=name):
        v1_env(**kwargs)


def test_v1_view_attribute_is_checked():
    env = v1_env()
    try:
        with pytest.raises(ValueError, match="overview"):
            env.unwrapped.view = "sideways"
        assert env.unwrapped.view == "follow"
    finally:
        env.close()


def test_window_takes_the_size_of_a_new_frame(monkeypatch):
    monkeypatch.setenv("SDL_VIDEODRIVER", "dummy")
    monkeypatch.setenv("SDL_AUDIODRIVER", "dummy")
    window = Window("test", 64, 64, fps=1000)
    try:
        window.show(one_floe(50.0, 50.0, size=64))
        wide = one_floe(50.0, 50.0, box=(200.0, 100.0), size=96)
        window.show(wide)
        assert window.screen.get_size() == (96, 48)
    finally:
        window.close()
