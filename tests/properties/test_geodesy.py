"""Behaviour and property tests of ``stereoplotter.geodesy`` (round trips, handedness, errors).

Book references are [1] = Kushtin & Lyskov 1984, ch. 2 §8–§11 (OCR L820–1340). Independent
references: pyproj's own ``+proj=cart`` (geocentric) and PROJ's transverse Mercator.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from numpy.testing import assert_allclose
from pyproj import CRS, Transformer

from stereoplotter.constants import ARCSEC_PER_RAD
from stereoplotter.errors import StereoplotterError
from stereoplotter.geodesy import (
    GeodesyRangeError,
    LocalFrame,
    axial_meridian,
    conventional_from_geographic,
    conventional_ordinate,
    gauss_kruger_from_geographic,
    gauss_kruger_from_local,
    gauss_kruger_from_local_corrections,
    gauss_kruger_from_local_direct,
    geocentric_from_geodetic,
    geocentric_from_local,
    geodetic_from_geocentric,
    geodetic_from_geocentric_book_iteration,
    geodetic_height,
    geographic_from_conventional,
    geographic_from_gauss_kruger,
    local_from_gauss_kruger,
    local_from_gauss_kruger_corrections,
    local_from_gauss_kruger_direct,
    local_from_geocentric,
    meridian_convergence,
    normal_height,
    split_conventional_ordinate,
    zone_from_longitude,
)

m = 1.0
mm = 1e-3 * m
arcsec = 1.0 / ARCSEC_PER_RAD
deg = math.pi / 180.0

CART = Transformer.from_crs(
    CRS.from_proj4("+proj=longlat +ellps=krass"),
    CRS.from_proj4("+proj=cart +ellps=krass"),
    always_xy=True,
)
BOOK_FRAME = LocalFrame.from_gauss_kruger(6140794.660, 235949.468, 500.0, zone=4)

latitudes = st.floats(min_value=-80.0, max_value=80.0)  # degrees
offsets = st.floats(min_value=-5.9, max_value=5.9)  # degrees from the axial meridian
zones = st.integers(min_value=1, max_value=60)
local_offsets = st.floats(min_value=-50_000.0, max_value=50_000.0)  # m
heights = st.floats(min_value=-100.0, max_value=5000.0)  # m


# --------------------------------------------------------------------------------------------
# zones and the conventional ordinate


def test_axial_meridians():
    # [1] §8 (L873): L₀ = 6N − 3°; zone 4 (the book's example) is 21°, zone 31 is 183° = −177°.
    assert axial_meridian(1) == pytest.approx(3 * deg)
    assert axial_meridian(4) == pytest.approx(21 * deg)
    assert axial_meridian(31) == pytest.approx(-177 * deg)


def test_zone_from_longitude():
    lon = np.radians([0.0, 5.999, 6.0, 21.0, 24.72, 179.9, -0.1, -177.0])
    assert zone_from_longitude(lon).tolist() == [1, 1, 2, 4, 5, 30, 60, 31]


def test_conventional_ordinate_book_example():
    # [1] §8, L875: N = 8, y = −55 451.54 m gives ȳ = 8 444 548.46 m (printed to 0.01 m).
    assert float(conventional_ordinate(8, -55451.54)) == pytest.approx(8444548.46, abs=1e-6)
    zone, y = split_conventional_ordinate(8444548.46)
    assert int(zone) == 8
    assert float(y) == pytest.approx(-55451.54, abs=1e-6)


def test_split_conventional_ordinate_arrays():
    zone, y = split_conventional_ordinate(np.array([4735949.468, 5300000.0]))
    assert zone.tolist() == [4, 5]
    assert_allclose(y, [235949.468, -200000.0], rtol=0, atol=1e-6)


@pytest.mark.parametrize("zone", [0, 61, -3])
def test_invalid_zone_number(zone):
    with pytest.raises(GeodesyRangeError, match=rf"zone = {zone} is outside .*1…60"):
        axial_meridian(zone)


def test_non_integer_zone():
    with pytest.raises(GeodesyRangeError, match=r"zone = 4\.5 is outside .*integer"):
        gauss_kruger_from_geographic(0.9, 0.4, 4.5)


def test_geodesy_errors_are_stereoplotter_errors():
    with pytest.raises(StereoplotterError, match="zone"):
        axial_meridian(0)
    assert issubclass(GeodesyRangeError, ValueError)


def test_invalid_latitude():
    with pytest.raises(GeodesyRangeError, match=r"latitude = '95°' is outside .*\[-90°, 90°\]"):
        gauss_kruger_from_geographic(math.radians(95.0), math.radians(21.0), 4)


def test_longitude_outside_zone():
    with pytest.raises(GeodesyRangeError, match=r"longitude = '30°' .*\[15°, 27°\] for zone 4"):
        gauss_kruger_from_geographic(math.radians(55.0), math.radians(30.0), 4)


def test_ordinate_without_zone_number():
    # A plain y (without N and 500 km) is not a conventional ordinate.
    with pytest.raises(GeodesyRangeError, match=r"conventional_ordinate_m = 235949\.468"):
        split_conventional_ordinate(235949.468)


def test_plain_ordinate_too_large():
    with pytest.raises(GeodesyRangeError, match=r"y_east_m = 600000\.0 .*\(-500000, 500000\)"):
        conventional_ordinate(4, 600000.0)


def test_conventional_ordinate_overflow():
    # 5° from the axial meridian on the equator is y ≈ 557 km: ȳ would read as the next zone.
    with pytest.raises(GeodesyRangeError, match=r"y_east_m = 557319\.48.* zone digit"):
        conventional_from_geographic(0.0, math.radians(14.0), zone=2)


def test_conventional_zone_without_epsg_code():
    # EPSG defines Pulkovo 1942 / Gauss-Kruger zones 2–32 only.
    with pytest.raises(GeodesyRangeError, match=r"zone = 1 is outside .*2…32"):
        conventional_from_geographic(math.radians(50.0), math.radians(3.0))


# --------------------------------------------------------------------------------------------
# Gauss–Krüger round trips and consistency


@given(latitudes, offsets, zones)
def test_gauss_kruger_round_trip(lat_deg, dl_deg, zone):
    # GK → geographic → GK within 1e-6 m.
    lat = math.radians(lat_deg)
    lon = axial_meridian(zone) + math.radians(dl_deg)
    x, y = gauss_kruger_from_geographic(lat, lon, zone)
    b, lon2 = geographic_from_gauss_kruger(x, y, zone)
    x2, y2 = gauss_kruger_from_geographic(b, lon2, zone)
    assert_allclose([x2, y2], [x, y], rtol=0, atol=1e-6 * m)


@given(latitudes, st.floats(min_value=-3.5, max_value=3.5), st.integers(min_value=2, max_value=32))
def test_conventional_matches_plain(lat_deg, dl_deg, zone):
    # EPSG:284NN equals the plain tmerc plus 1 000 000·N + 500 000 (1e-6 m), and inverts.
    # (|l| ≤ 3.5° keeps |y| < 500 km, which the conventional ordinate needs.)
    lat = math.radians(lat_deg)
    lon = axial_meridian(zone) + math.radians(dl_deg)
    x, y = gauss_kruger_from_geographic(lat, lon, zone)
    xc, ybar = conventional_from_geographic(lat, lon, zone)
    assert_allclose([xc, ybar], [x, conventional_ordinate(zone, y)], rtol=0, atol=1e-6 * m)
    b, lon2 = geographic_from_conventional(xc, ybar)
    x2, y2 = gauss_kruger_from_geographic(b, lon2, zone)
    assert_allclose([x2, y2], [x, y], rtol=0, atol=1e-6 * m)


def test_conventional_mixed_zones():
    lat = np.radians([55.0, 55.0])
    lon = np.radians([23.0, 25.0])  # zones 4 and 5
    x, ybar = conventional_from_geographic(lat, lon)
    assert split_conventional_ordinate(ybar)[0].tolist() == [4, 5]
    b, lon2 = geographic_from_conventional(x, ybar)
    assert_allclose([b, lon2], [lat, lon], rtol=0, atol=1e-12)


def test_scalar_and_array_calls_agree():
    xs = np.array([6140794.660, 6109939.518])
    ys = np.array([235949.468, 246316.596])
    b, lon = geographic_from_gauss_kruger(xs, ys, 4)
    for i in range(2):
        bi, li = geographic_from_gauss_kruger(xs[i], ys[i], 4)
        assert np.ndim(bi) == 0
        assert_allclose([bi, li], [b[i], lon[i]], rtol=0, atol=0)


def test_axial_meridian_maps_to_y_zero():
    x, y = gauss_kruger_from_geographic(np.radians([0.0, 40.0, 70.0]), 21 * deg, 4)
    assert_allclose(y, 0.0, rtol=0, atol=1e-9 * m)
    assert_allclose(x[0], 0.0, rtol=0, atol=1e-9 * m)


# --------------------------------------------------------------------------------------------
# meridian convergence


def test_convergence_sign_and_zero():
    # γ = 0 on the axial meridian; γ > 0 east of it in the northern hemisphere (A = α + γ), < 0
    # west of it, and the sign flips in the southern hemisphere.
    lat = np.radians([55.0, 55.0, 55.0, -55.0])
    lon = np.radians([21.0, 24.0, 18.0, 24.0])
    gamma = meridian_convergence(lat, lon, 4)
    assert abs(gamma[0]) < 1e-12
    assert gamma[1] > 0 > gamma[2]
    assert gamma[3] < 0


def test_convergence_is_the_grid_bearing_of_the_meridian():
    # Independent check: the grid bearing of a short meridian arc through the book's point O,
    # by finite differences of PROJ's forward projection, is −γ (within 0.001″).
    b, lon = BOOK_FRAME.latitude, BOOK_FRAME.longitude
    step = 1e-5
    x1, y1 = gauss_kruger_from_geographic(b + step, lon, 4)
    x0, y0 = gauss_kruger_from_geographic(b - step, lon, 4)
    bearing = math.atan2(y1 - y0, x1 - x0)
    assert_allclose(-bearing, BOOK_FRAME.convergence, rtol=0, atol=0.001 * arcsec)


# --------------------------------------------------------------------------------------------
# geocentric and heights


@given(latitudes, st.floats(min_value=-179.0, max_value=179.0), heights)
def test_geocentric_matches_pyproj_and_inverts(lat_deg, lon_deg, h):
    lat, lon = math.radians(lat_deg), math.radians(lon_deg)
    xyz = geocentric_from_geodetic(lat, lon, h)
    ref = CART.transform(lon_deg, lat_deg, h)
    assert_allclose(xyz, ref, rtol=0, atol=1e-6 * m)
    b, lon2, h2 = geodetic_from_geocentric(*xyz)
    assert_allclose(geocentric_from_geodetic(b, lon2, h2), xyz, rtol=0, atol=1e-6 * m)


@pytest.mark.parametrize("lat_deg", [5.0, 30.0, 55.0, 80.0])
def test_book_iteration_converges(lat_deg):
    # (2.15) converges to PROJ's exact inverse (0.1 mm after 4 approximations).
    xyz = geocentric_from_geodetic(math.radians(lat_deg), 0.3, 2490.0)
    _, steps = geodetic_from_geocentric_book_iteration(*xyz, iterations=4)
    b, _, h = geodetic_from_geocentric(*xyz)
    assert_allclose(steps[-1].height_m, h, rtol=0, atol=0.1 * mm)
    assert_allclose(steps[-1].latitude, b, rtol=0, atol=1e-5 * arcsec)


def test_normal_and_geodetic_heights():
    # (2.6) and (2.17): H = H^γ + ζ.
    assert float(geodetic_height(500.0, 20.0)) == 520.0
    assert float(normal_height(geodetic_height(500.0, 20.0), 20.0)) == 500.0


# --------------------------------------------------------------------------------------------
# the local system


@given(local_offsets, local_offsets, heights)
def test_local_round_trip(dx, dy, h):
    # GK → local → GK within 1e-6 m (rigorous §9 path both ways).
    x = BOOK_FRAME.origin_north_m + dx
    y = BOOK_FRAME.origin_east_m + dy
    local = local_from_gauss_kruger(BOOK_FRAME, x, y, h)
    assert_allclose(gauss_kruger_from_local(BOOK_FRAME, *local), [x, y, h], rtol=0, atol=1e-6)


@given(local_offsets, local_offsets, heights)
def test_local_geocentric_round_trip(X, Y, Z):
    g = geocentric_from_local(BOOK_FRAME, X, Y, Z)
    assert_allclose(local_from_geocentric(BOOK_FRAME, *g), [X, Y, Z], rtol=0, atol=1e-6 * m)


def test_local_round_trip_other_hemisphere_and_zone():
    frame = LocalFrame.from_geographic(math.radians(-33.0), math.radians(151.0), 40.0, zone=26)
    xyz = np.array([[12000.0, -8000.0, 300.0], [-40000.0, 25000.0, 10.0]]).T
    gk = gauss_kruger_from_local(frame, *xyz)
    assert_allclose(local_from_gauss_kruger(frame, *gk), xyz, rtol=0, atol=1e-6 * m)


def test_rotation_is_proper():
    r = BOOK_FRAME.rotation
    assert_allclose(r @ r.T, np.eye(3), rtol=0, atol=1e-15)
    assert np.linalg.det(r) == pytest.approx(1.0, abs=1e-15)


def _jacobian(f, p, step=1.0):
    p = np.asarray(p, dtype=float)
    cols = []
    for i in range(3):
        e = np.zeros(3)
        e[i] = step
        cols.append((np.array(f(*(p + e))) - np.array(f(*(p - e)))) / (2 * step))
    return np.array(cols).T


def test_handedness_gk_to_local_is_a_reflection():
    # conventions §3: (x north, y east, up) is left-handed, (X, Y, Z) right-handed, so the
    # linear part of GK → local has det < 0 in the (north, east) order, and > 0 in (east, north).
    p = (6120000.0, 240000.0, 800.0)
    jac = _jacobian(lambda x, y, h: local_from_gauss_kruger(BOOK_FRAME, x, y, h), p)
    assert np.linalg.det(jac[:2, :2]) < 0
    assert np.linalg.det(jac) < 0
    swapped = jac[:, [1, 0, 2]]  # columns in (east, north, up) order
    assert np.linalg.det(swapped) > 0
    # and the swap is the dominant part: X ≈ east, Y ≈ north (5e-3 absorbs the scale, δ₀ᵢ and
    # the turn of the normal over the 21 km from O, ≈ D/R = 3.3e-3).
    assert_allclose(jac, [[0, 1, 0], [1, 0, 0], [0, 0, 1]], rtol=0, atol=5e-3)


def test_local_axes_directions():
    # Y is grid north at O, Z is O's normal, the origin is the point O itself at H₀.
    f = BOOK_FRAME
    x0, y0, h0 = f.origin_north_m, f.origin_east_m, f.origin_height_m
    assert_allclose(local_from_gauss_kruger(f, x0, y0, h0), 0.0, rtol=0, atol=1e-6 * m)
    assert_allclose(local_from_gauss_kruger(f, x0, y0, h0 + 100.0), [0, 0, 100], atol=1e-6)
    # 1 km of grid is D = 1000(1 + k) on the ground, k ≈ −y₀²/(2R²) + H₀/R = −6.04e-4
    r = 6.3858e6
    ground = 1000.0 * (1 - y0**2 / (2 * r**2) + h0 / r)
    # due grid north: X ≈ −D·δ₀ᵢ ≈ −3 mm (arc-to-chord), Y ≈ D, Z ≈ −D²/(2R)
    X, Y, Z = local_from_gauss_kruger(f, x0 + 1000.0, y0, h0)
    assert abs(X) < 5 * mm
    assert Y == pytest.approx(ground, abs=2 * mm)
    assert Z == pytest.approx(-(1000.0**2) / (2 * r), abs=5 * mm)
    # due grid east: X ≈ D with the scale at the mean ordinate y₀ + 500 m, Y ≈ 0
    X, Y, _ = local_from_gauss_kruger(f, x0, y0 + 1000.0, h0)
    ground_east = 1000.0 * (1 - (y0 + 500.0) ** 2 / (2 * r**2) + h0 / r)
    assert X == pytest.approx(ground_east, abs=2 * mm)
    assert abs(Y) < 5 * mm


def test_local_scale_near_origin_is_one_plus_k():
    # (6.8) linearised (conventions §3): near O, b = 1 + k and a = −(1 + k)δ₀ᵢ → 0. Check the
    # derivatives of X, Y with respect to the GK east, north to 2e-7.
    f = BOOK_FRAME
    jac = _jacobian(
        lambda x, y, h: local_from_gauss_kruger(f, x, y, h),
        (f.origin_north_m, f.origin_east_m, f.origin_height_m),
    )
    # k from (2.31) at Δy → 0: (1 + A)(1 + H₀/R_A) − 1, A = −ε(1 − 5ε/6), ε = y₀²/(2R_m²).
    rm, ra = 6385777.26, 6379822.0
    eps = f.origin_east_m**2 / (2 * rm**2)
    expected = (1 - eps * (1 - 5 * eps / 6)) * (1 + f.origin_height_m / ra)
    assert_allclose([jac[0, 1], jac[1, 0]], expected, rtol=0, atol=2e-7)
    assert_allclose([jac[0, 0], jac[1, 1]], 0.0, rtol=0, atol=2e-7)


# --------------------------------------------------------------------------------------------
# the book's direct forms against the rigorous transform ([1] §10: about 1 cm up to 100 × 100 km)

# |Δx|, |Δy| ≤ 50 km and heights 0–1000 m: within 15 mm. The error grows by ≈ 8 mm per km of
# height difference at the 70 km corners (the spherical model of (2.26) ignores that ellipsoid
# normals are skew: 28 mm at h = 3000 m), so the book's "about 1 cm" holds near O's height.
GRID = np.array(
    [
        (dx, dy, h)
        for dx in (-50e3, -20e3, 0.0, 30e3, 50e3)
        for dy in (-50e3, 0, 50e3)
        for h in (0, 1000)
    ]
).T


def test_direct_forms_match_rigorous_forward():
    x = BOOK_FRAME.origin_north_m + GRID[0]
    y = BOOK_FRAME.origin_east_m + GRID[1]
    rigorous = np.array(local_from_gauss_kruger(BOOK_FRAME, x, y, GRID[2]))
    direct = np.array(local_from_gauss_kruger_direct(BOOK_FRAME, x, y, GRID[2]))
    corrections = np.array(local_from_gauss_kruger_corrections(BOOK_FRAME, x, y, GRID[2]))
    assert_allclose(direct, rigorous, rtol=0, atol=15 * mm)
    assert_allclose(corrections, rigorous, rtol=0, atol=15 * mm)


def test_direct_forms_match_rigorous_inverse():
    x = BOOK_FRAME.origin_north_m + GRID[0]
    y = BOOK_FRAME.origin_east_m + GRID[1]
    local = local_from_gauss_kruger(BOOK_FRAME, x, y, GRID[2])
    expected = np.array([x, y, GRID[2]])
    direct = np.array(gauss_kruger_from_local_direct(BOOK_FRAME, *local))
    corrections = np.array(gauss_kruger_from_local_corrections(BOOK_FRAME, *local))
    assert_allclose(direct, expected, rtol=0, atol=15 * mm)
    assert_allclose(corrections, expected, rtol=0, atol=15 * mm)


def test_correction_form_is_reflected_similarity():
    # (2.30) as a map (Δx, Δy) → (X, Y) is [[−(1+k)δ, 1+k], [1+k, (1+k)δ]]: det < 0, the (6.8)
    # form with b = 1 + k, a = −(1 + k)δ₀ᵢ (conventions §3).
    p = (BOOK_FRAME.origin_north_m - 30e3, BOOK_FRAME.origin_east_m + 10e3, 2490.0)
    jac = _jacobian(lambda x, y, h: local_from_gauss_kruger_corrections(BOOK_FRAME, x, y, h), p)
    assert np.linalg.det(jac[:2, :2]) < 0
