"""Acceptance of the synthetic photographs.

Independent computation: the target centroids measured in rendered eyepiece views are compared
with Eq. (2.53) (``object_to_photo``) of the true ground point plus the film deformation — the
renderer never calls ``object_to_photo`` (it goes the other way, photo → ground, by ray
marching), so agreement checks the whole inverse mapping and the view geometry.
"""

from __future__ import annotations

import dataclasses
import hashlib

import numpy as np
import pytest

from stereoplotter.errors import StereoplotterError
from stereoplotter.geometry.collinearity import object_to_photo
from stereoplotter.imagery.cache import ViewCache
from stereoplotter.imagery.eyepiece import anaglyph, eyepiece_view, view_to_photo
from stereoplotter.imagery.photo import PhotoRaster, photo_geometry, render_photo, render_region
from stereoplotter.imagery.raytrace import ground_heights_m, terrain_bounds_m
from stereoplotter.io.images import png_bytes
from stereoplotter.io.scenario_file import load_scenario
from stereoplotter.scenario.model import Hill, Terrain
from stereoplotter.scenario.synthetic import film_deformed

M = 6.0
SIZE = 64


@pytest.fixture(scope="module")
def pair60():
    return load_scenario("pair60")


@pytest.fixture(scope="module")
def cache(pair60):
    return ViewCache(pair60)


def predicted_mm(scenario, side, point):
    ext = scenario.photo(side).exterior
    cam = scenario.camera
    xy = object_to_photo(
        np.array(point.local_m),
        ext.centre,
        ext.rotation,
        cam.focal_length_mm,
        cam.principal_point_mm,
    )
    return film_deformed(scenario.photo(side), xy)


def target_centroid_px(view, magnification):
    """Centroid (column, row) of the white premark in a view centred on it: brightness above
    the dark surround's level, in a box of ± one premark side around the view centre (the
    square is ±side/2, the dark surround ±1.5 side; a side is 0.1 mm = ``magnification`` view
    px)."""
    half = round(magnification)
    c = (view.shape[0] - 1) / 2.0
    lo, hi = int(np.floor(c)) - half + 1, int(np.ceil(c)) + half
    win = view[lo:hi, lo:hi].astype(float)
    w = np.clip(win - np.round(255 * 0.08), 0.0, None)
    rows, cols = np.mgrid[lo:hi, lo:hi]
    return float((w * cols).sum() / w.sum()), float((w * rows).sum() / w.sum())


def measured_targets(scenario, cache, magnification=M, size=SIZE):
    """Per control point imaged on both photos: predicted and measured photo x, y [mm]."""
    out = {}
    fmt = scenario.camera.format_mm / 2 - 2.0
    for p in scenario.points_with_role("control"):
        pred = {s: predicted_mm(scenario, s, p) for s in ("left", "right")}
        if any(np.abs(v).max() > fmt for v in pred.values()):
            continue
        meas = {}
        for s in ("left", "right"):
            view = cache.view(s, *pred[s], 0.0, magnification, size)
            u, v = target_centroid_px(view, magnification)
            meas[s] = np.array(view_to_photo(u, v, *pred[s], 0.0, magnification, size))
        out[p.id] = (pred, meas)
    return out


def test_target_centroids_within_quarter_pixel(pair60, cache):
    targets = measured_targets(pair60, cache)
    assert len(targets) >= 4
    view_px_mm = 0.1 / M
    worst = max(
        np.hypot(*(meas[s] - pred[s])) / view_px_mm
        for pred, meas in targets.values()
        for s in ("left", "right")
    )
    assert worst < 0.25


def test_y_parallax_at_targets_below_one_micrometre(pair60, cache):
    # With the true orientation both predictions come from the same ground point, so the model's
    # y-parallax there is zero; what the rendering adds is the difference of the y errors.
    # Measured at x20 (view pixel 5 um), as the operator clears parallax at high magnification.
    targets = measured_targets(pair60, cache, 20.0, 128)
    q_um = [
        1000 * ((meas["left"][1] - pred["left"][1]) - (meas["right"][1] - pred["right"][1]))
        for pred, meas in targets.values()
    ]
    assert max(abs(q) for q in q_um) < 1.0


def test_rotated_view_keeps_the_target_at_the_mark(pair60, cache):
    p = pair60.points_with_role("control")[0]
    xy = predicted_mm(pair60, "left", p)
    kappa = np.deg2rad(30.0)
    view = cache.view("left", *xy, kappa, M, SIZE)
    u, v = target_centroid_px(view, M)
    x, y = view_to_photo(u, v, *xy, kappa, M, SIZE)
    assert np.hypot(x - xy[0], y - xy[1]) / (0.1 / M) < 0.25


def steep(scenario):
    # A 600 m high, 150 m radius hill under the left photo: slopes up to 4·e^(-1/2) = 2.4 (68°),
    # steeper than any ray (the frame-corner rays lean atan(127/70) = 61° from the vertical).
    hills = (Hill(-300.0, 200.0, 600.0, 150.0), Hill(300.0, -900.0, -400.0, 120.0))
    return dataclasses.replace(scenario, terrain=Terrain(150.0, (0.05, -0.03), hills))


def test_steep_terrain_and_frame_edges_have_finite_exact_heights(pair60):
    sc = steep(pair60)
    bounds = terrain_bounds_m(sc, 6000.0)
    t = np.linspace(-93.0, 93.0, 187)
    X, Y = np.meshgrid(t, t)
    xy = np.stack([X, Y], axis=-1)
    Z = ground_heights_m(sc, "left", xy, bounds)
    assert np.isfinite(Z).all()
    ext = sc.photo("left").exterior
    d = np.einsum("ij,...j->...i", ext.rotation, np.stack([X, Y, -70.0 + 0 * X], axis=-1))
    G = ext.centre + (Z - ext.centre[2])[..., None] * d / d[..., 2:3]
    assert np.abs(sc.terrain.height_m(G[..., 0], G[..., 1]) - Z).max() < 1e-3
    # highest root: a dense independent march (0.5 m) finds no terrain above the ray before Z
    zs = np.arange(bounds[1], bounds[0], -0.5)
    for i, j in [(93, 93), (0, 0), (186, 186), (60, 80), (100, 40)]:
        dz = zs - ext.centre[2]
        k = d[i, j]
        g = (
            sc.terrain.height_m(ext.centre[0] + dz * k[0] / k[2], ext.centre[1] + dz * k[1] / k[2])
            - zs
        )
        first = zs[np.argmax(g >= 0)]
        assert abs(first - Z[i, j]) < 0.6


def test_steep_render_has_texture_to_the_frame_edges(pair60):
    raster = render_photo(steep(pair60), "left", pixel_mm=0.25)
    inside = raster.image[20:-20, 20:-20]
    assert inside.std() > 10 and (inside > 0).mean() > 0.95


def test_same_seed_same_bytes_and_tiles_equal_the_whole_photo(pair60):
    a = render_photo(pair60, "right", pixel_mm=0.3, seed=7)
    b = render_photo(pair60, "right", pixel_mm=0.3, seed=7)
    c = render_photo(pair60, "right", pixel_mm=0.3, seed=8)
    digest = [hashlib.sha256(png_bytes(r.image)).hexdigest() for r in (a, b, c)]
    assert digest[0] == digest[1] != digest[2]
    geo = photo_geometry(pair60, "right", 0.3, seed=7)
    np.testing.assert_array_equal(render_region(geo, 100, 228, 300, 428), a.image[100:228, 300:428])


def test_two_caches_serve_identical_views(pair60, cache):
    other = ViewCache(pair60)
    for args in [("left", 3.0, -4.0, 0.2, 6.0, 128), ("right", -50.0, 20.0, -0.1, 1.5, 96)]:
        assert png_bytes(cache.view(*args)) == png_bytes(other.view(*args))


def test_view_of_a_raster_matches_the_cache(pair60, cache):
    raster = cache.raster("left")
    view = eyepiece_view(raster, 10.0, 5.0, 0.0, magnification=0.625, size_px=64)
    np.testing.assert_array_equal(view, cache.view("left", 10.0, 5.0, 0.0, 0.625, 64))


def test_pixel_mapping_round_trip():
    r = PhotoRaster(np.zeros((3, 3), np.uint8), 0.5, (-0.5, 0.5), "left")
    assert r.to_pixel(0.0, 0.0) == (1.0, 1.0)
    assert r.to_photo(2, 0) == (0.5, 0.5)


def test_anaglyph_channels():
    left = np.full((4, 4), 200, np.uint8)
    right = np.full((4, 4), 50, np.uint8)
    rgb = anaglyph(left, right)
    assert rgb.shape == (4, 4, 3) and tuple(rgb[0, 0]) == (200, 50, 50)


def test_settings_beyond_the_stops_are_refused(cache):
    with pytest.raises(StereoplotterError, match=r"magnification must be in \[0.5, 60\]"):
        cache.view("left", 0.0, 0.0, 0.0, 100.0, 64)
    with pytest.raises(StereoplotterError, match="side must be one of"):
        cache.view("middle", 0.0, 0.0, 0.0, 6.0, 64)
