"""The pixel robot's eye (``tests/browser/pixel_robot.py``) on drawn eyepieces with a planted
offset: a textured field found to a tenth of a pixel, the mark itself never matched, a field
of stripes (one direction only) rejected as ambiguous."""

from __future__ import annotations

import numpy as np
from scipy.ndimage import gaussian_filter, shift

from tests.browser.pixel_robot import match, substitute_offset

SIZE = 256


def _eyepiece(grey: np.ndarray) -> np.ndarray:
    """A grey field as the page draws it: RGB, the red mark (dot and ring) at the centre."""
    rgb = np.repeat(np.clip(grey, 0, 255)[..., None], 3, axis=2)
    yy, xx = np.mgrid[0:SIZE, 0:SIZE]
    r = np.hypot(xx - (SIZE - 1) / 2, yy - (SIZE - 1) / 2)
    mark = (r < 2.5) | (np.abs(r - 9) < 0.75)
    rgb[mark] = (255, 64, 48)
    return rgb.astype(np.uint8)


def _texture(seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    big = gaussian_filter(rng.normal(0, 1, (SIZE + 64, SIZE + 64)), 2.0)
    return 128 + 40 * big / big.std()


def test_a_textured_field_is_found_to_a_tenth_of_a_pixel():
    field = _texture(1)
    for planted in [(7.3, -12.6), (-41.25, 30.5), (0.4, 0.2)]:  # (x, y) of the right view, px
        left = field[32:32 + SIZE, 32:32 + SIZE]
        moved = shift(field, (planted[1], planted[0]), order=3, mode="nearest")
        right = moved[32:32 + SIZE, 32:32 + SIZE]
        m = match(_eyepiece(left), _eyepiece(right), 20)
        assert m is not None
        assert abs(m.dx_px - planted[0]) < 0.1 and abs(m.dy_px - planted[1]) < 0.1, (m, planted)
        assert abs(m.q_um + planted[1] * 5.0) < 0.5  # ×20: 5 µm of photo a pixel, y up


def test_a_search_near_a_prediction_finds_the_same_offset():
    field = _texture(2)
    left = field[32:32 + SIZE, 32:32 + SIZE]
    right = shift(field, (20.0, -15.0), order=3, mode="nearest")[32:32 + SIZE, 32:32 + SIZE]
    m = match(_eyepiece(left), _eyepiece(right), 6, predict_px=(-14.0, 21.0), radius_px=4.0)
    assert m is not None and abs(m.dx_px + 15.0) < 0.1 and abs(m.dy_px - 20.0) < 0.1
    assert match(_eyepiece(left), _eyepiece(right), 6, predict_px=(30.0, -30.0),
                 radius_px=4.0) is None


def test_stripes_along_one_direction_are_rejected_as_ambiguous():
    yy, xx = np.mgrid[0:SIZE, 0:SIZE]
    stripes = 128 + 30 * np.sin(2 * np.pi * (xx + 0.3 * yy) / 9.0)
    m = match(_eyepiece(stripes), _eyepiece(np.roll(stripes, 5, axis=1)), 20)
    assert m is None, m


def test_a_match_beyond_the_reach_is_refused():
    """An offset of 90 px is found within the full search (100 px) and refused with a reach
    of 85 px (the search beyond the field then moves b_y or Z on)."""
    field = _texture(3)
    left = field[32:32 + SIZE, 32:32 + SIZE]
    right = shift(field, (0.0, -90.0), order=3, mode="nearest")[32:32 + SIZE, 32:32 + SIZE]
    m = match(_eyepiece(left), _eyepiece(right), 2)
    assert m is not None and abs(m.dx_px + 90.0) < 0.2 and abs(m.dy_px) < 0.2, m
    assert match(_eyepiece(left), _eyepiece(right), 2, reach_px=85.0) is None


def test_a_substitute_lies_within_the_grades_reach_towards_the_others():
    """e12's point 3 near the top edge of the left photo (the overview's places for one
    trainee): the substitute 10 mm from it, inside 0.2·c = 14 mm (c = 70 mm), and nearer the
    others' mean than the point."""
    points = {1: (-2.5282, 3.1462), 2: (72.5923, 1.776), 3: (-1.1502, 86.1315),
              4: (74.3791, 83.6101), 5: (-3.7574, -70.876), 6: (63.9533, -71.4277)}
    dx, dy = substitute_offset(points, 3)
    assert abs(np.hypot(dx, dy) - 10.0) < 1e-3 and np.hypot(dx, dy) <= 0.2 * 70.0
    mean = np.mean([points[k] for k in (1, 2, 4, 5, 6)], axis=0)
    sub = np.array(points[3]) + (dx, dy)
    assert np.hypot(*(sub - mean)) < np.hypot(*(np.array(points[3]) - mean)) - 9.0
