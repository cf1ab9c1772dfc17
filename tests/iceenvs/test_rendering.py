"""Tests of iceenvs.rendering: floe and thickness-distribution pictures, and the window."""
import math
import sys

import numpy as np
import pytest
from gymnasium.error import DependencyNotInstalled

pygame = pytest.importorskip("pygame")

from iceenvs.rendering import (  # noqa: E402
    BACKGROUND, CHAIN, ITD_BACKGROUND, ITD_TARGET, Window, draw_floes, draw_itd,
)


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
