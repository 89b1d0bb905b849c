"""The pixel robot's judgement: what a trainee sees in the two eyepieces, and what it turns.

No page, no core here: the decisions take the two eyepiece images (RGB arrays of the canvases the
page draws, the measuring mark at their centre) and return parallaxes and turns. A driver
(:class:`Eyes`: ``tests/browser/pixel_page.py`` drives the instrument page in Chromium) shows
the images and carries the turns out.

**Measuring the parallax at a point.** The left eyepiece's centre (around the mark, the mark itself
masked out) is searched for in the right eyepiece — turned back first by the difference of the
carriers' κ the wheels show (:func:`view`) — by normalised cross-correlation, masked (Padfield's
form, every sum an FFT correlation), of the grey level less its blur (:data:`HIGH_PASS_PX`),
sub-pixel by a parabola through the peak on each axis. The offset of the match from the right
eyepiece's centre is the parallax as the eye sees it: horizontal = x-parallax, vertical =
y-parallax, in screen pixels of ``SCREEN_PIXEL_MM / magnification`` mm of photo. Coarse to fine
(:meth:`Robot.fine`): ×2 finds the detail in a 12.8 mm field (one pixel 50 µm), ×6 and then ×20
measure it (16.7 µm, 5 µm a pixel), each searched near the coarser offset, Z set before each
finer look to clear the x-parallax (:meth:`Robot.fuse`, as a trainee fuses the detail). A ×20
reading is the mean of :data:`DITHER` looks with Y stepped through the step the page draws the
marks at (:meth:`Robot.steady`). A match is rejected where its peak is weak (:data:`MIN_PEAK`),
where a second peak away from it is nearly as high (:data:`MIN_MARGIN`: the striped
low-contrast fields), at the search's edge, or where the finer offset lies far from the coarser
one (:data:`AGREE_PX`). Where a point's own field is striped or plain, the marks are moved to
the most detailed place next to it (:func:`textured_spot`).

**Relative orientation** (:class:`Robot`). Z is set to clear the x-parallax (its effect learnt
by a probe setting at point 1, :meth:`Robot.learn_z`; the wheel read after the page has
redrawn it); cycles of the conventional method's element-by-element clearing (:data:`CLASSIC`,
each element's effect learnt by a probe turn) bring every detail near the mark; then at each
standard point the robot turns each of the five elements (κ_л, κ_п, k_α,л, k_α,п, k_ω,п) by a
probe step and back, the change per unit its row of the Jacobian; the turns that null the six
y-parallaxes in weighted least squares (:data:`WEIGHT` by magnification) are made at once; the
points are measured again (at ×20 near the predicted parallax), and so on until all the points
read at ×20 under :data:`DONE_SHARE` of the tolerance or :data:`PASSES` passes are done; the
last pass only measures the step before it. Where a point is not found only
:data:`PARTIAL_SHARE` of the step is taken, and near the solution :data:`NEAR_SHARE` of one
solved from the ×20 readings alone (averaging the readings' scatter over the passes). A step
that loses a point is turned back whole, the points measured again there, and a shorter one
(:data:`LOST_SHARE`) taken; a step that leaves the parallaxes worse is halved (half of it
turned back) and the points measured again, or turned back whole after the last pass.

**Beyond the field** (``wide``, the mountain exam e12 on the SD-3): a point whose detail the
×2 field does not show is searched for by b_y (:meth:`Robot.far`: b_y's effect on the right
view learnt by a probe, then steps of about 4 mm of y-parallax each way, the y-parallax the
shift added counted in and b_y set back after the clearing turn) and by Z over ±60 mm (the
marks put back on the point after each setting of Z: on the SD-3 Z moves the left mark off
it), a match taken only where Z then fuses it (:meth:`Robot.coarse_wide`). An unusable
standard point is measured at its substitute (``substitutes``: the marks go to the point, then
on by the offset, :func:`substitute_offset`).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Protocol

import numpy as np
from scipy import fft as sfft
from scipy.ndimage import binary_dilation, gaussian_filter, rotate

#: The page's screen pixel at ×1 (the server's ``SCREEN_PIXEL_MM``, sent in its first message). [mm]
SCREEN_PIXEL_MM = 0.1
#: The relative elements the robot turns (the page's control names), and their probe steps
#: (κ in rad, the correction knobs in tan: ≈ 0.2–0.7 mm of y-parallax, 4–14 px at ×2). [—]
ELEMENTS = ("kappa_left", "kappa_right", "k_alpha_left", "k_alpha_right", "k_omega_right")
PROBE = {"kappa_left": 3e-3, "kappa_right": 3e-3, "k_alpha_left": 3e-3, "k_alpha_right": 3e-3,
         "k_omega_right": 3e-3}
#: Magnifications: the finding one and the measuring ones, finest first.
FIND_MAG, FINE_MAGS = 2, (20, 6)
#: Side of the template cut from the left eyepiece's centre, by magnification. [px]
TEMPLATE_PX = {2: 96, 6: 96, 20: 160}
#: The window of the detail search at ×2 (≈ the ×20 template) [px]; how much more fine
#: detail a spot needs than the point's own place to be preferred [—]; its reach [px].
SPOT_PX, SPOT_GAIN, SPOT_REACH_PX = 10, 2.0, 50
#: The reach of the detail search at ×20. [px]
FINE_REACH_PX = 100
#: The probe turn of X and Y. [mm]
XY_PROBE = 1.0
#: The high-pass filter's Gaussian (the grey level less its blur). [px]
HIGH_PASS_PX = 6.0
#: Largest offset searched (the template then overlaps the right view by half or more). [px]
SEARCH_PX = 100
#: The measuring mark's disc masked out of both images (the page draws a ring of 9 px). [px]
MARK_RADIUS_PX = 13
#: Smallest correlation peak accepted; least lead of the peak over any other peak further than
#: :data:`PEAK_EXCLUSION_PX` away (assumed: the striped fields correlate 0.63–0.74 with their
#: own match, so the lead, not the peak alone, rejects a false match). [—], [px]
MIN_PEAK, MIN_MARGIN, PEAK_EXCLUSION_PX = 0.3, 0.05, 6
#: A finer match must lie within this many pixels (of the coarser look) of the coarser one:
#: the ×2 look is off by up to ≈ 150 µm = 3 of its pixels where the field is far from
#: oriented (measured: one seed near its solution, ×2 against the grade's true q). [px]
AGREE_PX = 4.0
#: Where a search is near a prediction, the rivals that count lie within this many search radii
#: of it (a peak far from where the coarser look put the detail cannot be taken for it). [—]
LOCAL_RIVAL = 3.0
#: Margin kept between the searched offset and the eyepiece's edge. [px]
EDGE_PX = 8
#: The robot claims when the largest measured |q| is under this share of the tolerance. [—]
DONE_SHARE = 0.25
#: Weights of a y-parallax in the least squares by the magnification it was read at: a ×6
#: reading was off by 5–40 µm where ×20 agreed with the grade's true q within ≈ 3 µm (one
#: run, two seeds, read against the true q only while developing). [—]
WEIGHT = {20: 1.0, 6: 0.2, 2: 0.05}
#: Least-squares passes at most.
PASSES = 12
#: A step is halved (half of it turned back, the points measured again) where it lost a point
#: found before it or left the largest |q| of the points read both times above
#: ``WORSE_FACTOR`` × its value before plus ``WORSE_UM`` (readings' scatter); at most
#: ``HALVINGS`` times in a row. [—], [µm], [—]
WORSE_FACTOR, WORSE_UM, HALVINGS = 1.5, 10.0, 3
#: The share of a least-squares step taken where a point was not found (five points fix the
#: five elements exactly, with nothing to check a wrong reading against). [—]
PARTIAL_SHARE = 0.5
#: Where every point is found, at least ``NEAR_FINE`` of them at ×20, and every ×20 reading
#: is under ``NEAR_UM``, ``NEAR_SHARE`` of each step is taken: a ×20 reading scatters by a
#: few µm, at times up to 18 µm, about the true q (the verbose runs in docs/trainer.md); a
#: full step carries that scatter whole into the next pass, half a step (the iteration
#: q ← q/2 − e/2) leaves ≈ 1/√3 of it. There the step is solved from the ×20 readings alone:
#: a ×6 reading near the solution was 22–34 µm off where ×20 agreed within a few µm, and a
#: step solved with it moved its point by most of it (docs/trainer.md, run "pixel 4").
#: [µm], [—], [—]
NEAR_UM, NEAR_SHARE, NEAR_FINE = 25.0, 0.5, 5
#: A step that lost a point found before it is turned back whole (the wheels turned back by
#: the amounts they were turned), the points measured again where all were found, the lost
#: points' Jacobian rows probed again, and the next step taken at ``LOST_SHARE`` (to its
#: power, after retreats in a row). [—]
LOST_SHARE = 0.25


class Eyes(Protocol):
    """What the robot does on the page: go to a standard point, turn an element, look."""

    def go_to(self, point: int) -> None: ...

    def set(self, control: str, value: float) -> None: ...

    def wheel(self, control: str) -> float:
        """The value a control's wheel shows."""
        ...

    def turn(self, control: str, delta: float) -> None: ...

    def look(self, magnification: int) -> tuple[np.ndarray, np.ndarray]:
        """The left and right eyepiece canvases as drawn (H×W×3 uint8)."""
        ...


@dataclass(frozen=True)
class Match:
    """Where the left eyepiece's centre lies in the right one: offset from the right centre in
    screen pixels (x right, y down), the correlation peak and its lead over the next peak."""

    dx_px: float
    dy_px: float
    peak: float
    margin: float
    magnification: int

    @property
    def um_per_px(self) -> float:
        return SCREEN_PIXEL_MM / self.magnification * 1000.0

    @property
    def q_um(self) -> float:
        """The y-parallax seen (photo y up: a detail lower on the right is +). [µm]"""
        return -self.dy_px * self.um_per_px

    @property
    def p_um(self) -> float:
        """The x-parallax seen. [µm]"""
        return self.dx_px * self.um_per_px


def grey_and_mask(rgb: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The photo's grey level (green channel) and the mask of pixels that show the photo: the
    mark's disc and any coloured pixel (the red mark, the page's yellow notes) left out."""
    rgb = np.asarray(rgb, float)
    grey = rgb[..., 1] - gaussian_filter(rgb[..., 1], HIGH_PASS_PX)  # the fields' edges, texture
    h, w = grey.shape
    yy, xx = np.mgrid[0:h, 0:w]
    r2 = (xx - (w - 1) / 2) ** 2 + (yy - (h - 1) / 2) ** 2
    coloured = (np.abs(rgb[..., 0] - rgb[..., 1]) > 2) | (np.abs(rgb[..., 2] - rgb[..., 1]) > 2)
    coloured = binary_dilation(coloured, iterations=int(2 * HIGH_PASS_PX))
    return grey, (r2 > (MARK_RADIUS_PX + 2 * HIGH_PASS_PX) ** 2) & ~coloured


def view(eyes: Eyes, magnification: int) -> tuple[np.ndarray, np.ndarray]:
    """The two eyepieces, the right one turned back by the difference of the carriers' κ as
    their wheels show it (the page turns each field by its carrier's κ; a relative turn of a
    few hundredths of a radian biases a correlation by up to 5 px where the detail lies on one
    side of the field — measured: 4.9 px at ×2, point 4 of one seed, Δκ = −0.033 rad)."""
    left, right = eyes.look(magnification)
    turn = eyes.wheel("kappa_right") - eyes.wheel("kappa_left")
    if abs(turn) > 1e-4:
        right = rotate(np.asarray(right, float), np.degrees(turn), reshape=False, order=1,
                       mode="nearest")
    return left, right


def textured_spot(rgb: np.ndarray, reach_px: float) -> tuple[float, float]:
    """Where near the centre (within ``reach_px``) the left eyepiece shows the most fine detail
    (the energy of the high-passed grey level over a :data:`SPOT_PX` window, the mark's disc
    left out): the offset from the centre in screen pixels (x right, y down). A point's
    y-parallax is measured on such a detail next to it where its own field is a low-contrast
    stripe (the y-parallax changes by well under a micrometre over a millimetre of photo once
    the model is near its orientation)."""
    grey = np.asarray(rgb, float)[..., 1]
    fine = grey - gaussian_filter(grey, 1.5)
    _, ok = grey_and_mask(rgb)
    energy = gaussian_filter(fine**2 * ok, SPOT_PX / 2) / np.maximum(
        gaussian_filter(ok.astype(float), SPOT_PX / 2), 1e-3)
    h, w = grey.shape
    yy, xx = np.mgrid[0:h, 0:w]
    dx, dy = xx - (w - 1) / 2, yy - (h - 1) / 2
    energy = np.where(np.hypot(dx, dy) <= reach_px, energy, -1)
    centre = float(np.max(np.where(np.hypot(dx, dy) <= SPOT_PX, energy, -1)))
    i, j = np.unravel_index(int(np.argmax(energy)), energy.shape)
    if energy[i, j] < SPOT_GAIN * centre:
        return 0.0, 0.0
    return float(dx[i, j]), float(dy[i, j])


def masked_ncc(t: np.ndarray, a: np.ndarray, g: np.ndarray, b: np.ndarray,
               min_overlap: float = 0.5) -> np.ndarray:
    """Normalised cross-correlation of template ``t`` (mask ``a``) at every position overlapping
    image ``g`` (mask ``b``), only pixels valid in both counted (Padfield 2012, every sum one
    FFT correlation; the three template and three image transforms made once): ``out[i, j]``
    for the template's top-left corner at row i − (th − 1), column j − (tw − 1); −1 where fewer
    than ``min_overlap`` of the template's pixels overlap."""
    a = a.astype(float)
    b = b.astype(float)
    t = t * a
    gb = g * b
    shape = (g.shape[0] + t.shape[0] - 1, g.shape[1] + t.shape[1] - 1)
    fast = tuple(sfft.next_fast_len(n, real=True) for n in shape)

    def spectrum(x: np.ndarray) -> np.ndarray:
        return sfft.rfft2(x, fast)

    flipped = [spectrum(x[::-1, ::-1]) for x in (a, t, t * t)]
    fa, ft, ftt = flipped
    fb, fgb, fgg = (spectrum(x) for x in (b, gb, gb * g))

    def corr(fx: np.ndarray, fy: np.ndarray) -> np.ndarray:
        return sfft.irfft2(fx * fy, fast)[:shape[0], :shape[1]]

    n = corr(fa, fb)
    st, sg = corr(ft, fb), corr(fa, fgb)
    stt, sgg = corr(ftt, fb), corr(fa, fgg)
    stg = corr(ft, fgb)
    n_safe = np.maximum(n, 1.0)
    num = stg - st * sg / n_safe
    den = (stt - st**2 / n_safe) * (sgg - sg**2 / n_safe)
    ok = (den > 1e-6) & (n > min_overlap * a.sum())
    return np.where(ok, num / np.sqrt(np.maximum(den, 1e-12)), -1.0)


def _vertex(c_m: float, c_0: float, c_p: float) -> float:
    d = c_m - 2 * c_0 + c_p
    return 0.0 if d >= -1e-9 else float(np.clip(0.5 * (c_m - c_p) / d, -1.0, 1.0))


def match(
    left: np.ndarray, right: np.ndarray, magnification: int,
    predict_px: tuple[float, float] | None = None, radius_px: float | None = None,
    strict: bool = True, reach_px: float = SEARCH_PX,
) -> Match | None:
    """The left eyepiece's centre found in the right eyepiece (see the module docstring), or
    None where the match is weak or ambiguous. ``predict_px``, ``radius_px``: search only
    offsets within ``radius_px`` of ``predict_px``; the peak's lead is then taken over the
    peaks within :data:`LOCAL_RIVAL` radii of the prediction. ``reach_px``: the largest
    offset searched on each axis (a match at it is refused: the detail may lie beyond)."""
    gl, ml = grey_and_mask(left)
    gr, mr = grey_and_mask(right)
    h, w = gl.shape
    size = TEMPLATE_PX.get(magnification, 96)
    c0 = (h - size) // 2, (w - size) // 2
    t = gl[c0[0]:c0[0] + size, c0[1]:c0[1] + size]
    a = ml[c0[0]:c0[0] + size, c0[1]:c0[1] + size]
    ncc = masked_ncc(t, a, gr, mr)
    oy, ox = np.mgrid[0:ncc.shape[0], 0:ncc.shape[1]]
    # offsets of the template from its place in the left view
    oy, ox = oy - (size - 1) - c0[0], ox - (size - 1) - c0[1]
    allowed = (np.abs(oy) <= reach_px) & (np.abs(ox) <= reach_px)
    if predict_px is not None and radius_px is not None:
        allowed &= np.hypot(ox - predict_px[0], oy - predict_px[1]) <= radius_px
    if not allowed.any():
        return None
    masked = np.where(allowed, ncc, -np.inf)
    i, j = np.unravel_index(int(np.argmax(masked)), ncc.shape)
    peak = float(ncc[i, j])
    far = np.hypot(oy - oy[i, j], ox - ox[i, j]) > PEAK_EXCLUSION_PX
    inside = (np.abs(oy) <= SEARCH_PX) & (np.abs(ox) <= SEARCH_PX)
    if predict_px is not None and radius_px is not None:
        # near a prediction only a rival near it can mislead (a stripe's ridge still does)
        inside &= np.hypot(ox - predict_px[0], oy - predict_px[1]) <= LOCAL_RIVAL * radius_px
    second = float(np.max(np.where(far & inside, ncc, -1)))
    margin = peak - second
    if strict and (peak < MIN_PEAK or margin < MIN_MARGIN):
        return None
    if max(abs(oy[i, j]), abs(ox[i, j])) >= reach_px:  # at the search's edge: beyond it
        return None
    di = _vertex(ncc[i - 1, j], ncc[i, j], ncc[i + 1, j])
    dj = _vertex(ncc[i, j - 1], ncc[i, j], ncc[i, j + 1])
    return Match(float(ox[i, j] + dj), float(oy[i, j] + di), peak, margin, magnification)


def fits(offset_px: tuple[float, float], from_mag: int, to_mag: int) -> bool:
    """Whether an offset seen at ``from_mag`` stays inside the search area of ``to_mag``."""
    k = to_mag / from_mag
    return max(abs(offset_px[0]), abs(offset_px[1])) * k <= 0.6 * SEARCH_PX


def refine(eyes: Eyes, m: Match) -> Match:
    """A match carried to finer magnifications (×6, then ×20) while the offset stays in the
    finer field: each finer look searched within :data:`AGREE_PX` pixels of the coarser one."""
    for mag in sorted(FINE_MAGS):
        if mag <= m.magnification or not fits((m.dx_px, m.dy_px), m.magnification, mag):
            continue
        k = mag / m.magnification
        images = view(eyes, mag)
        fine = match(*images, mag, (m.dx_px * k, m.dy_px * k), AGREE_PX * k)
        if fine is None:
            break
        m = fine
    return m


def measure(eyes: Eyes, predict_um: tuple[float, float] | None = None,
            radius_um: float = 40.0) -> Match | None:
    """The parallax at the place the marks are on, coarse to fine (module docstring).
    ``predict_um`` (x-, y-parallax as :class:`Match` gives them) skips the finding look where
    the prediction holds at ×20."""
    if predict_um is not None:
        um = SCREEN_PIXEL_MM / FINE_MAGS[0] * 1000.0
        guess = (predict_um[0] / um, -predict_um[1] / um)
        if fits(guess, FINE_MAGS[0], FINE_MAGS[0]):
            m = match(*view(eyes, FINE_MAGS[0]), FINE_MAGS[0], guess, radius_um / um)
            if m is not None:
                return m
    coarse = match(*view(eyes, FIND_MAG), FIND_MAG)
    return None if coarse is None else refine(eyes, coarse)


@dataclass
class Orientation:
    """The robot's record of a relative orientation: what it measured and turned."""

    tolerance_um: float
    points: tuple[int, ...] = (1, 2, 3, 4, 5, 6)
    jacobian: dict[int, np.ndarray] = field(default_factory=dict)  # µm of q per unit
    q_um: dict[int, float] = field(default_factory=dict)
    mag: dict[int, int] = field(default_factory=dict)  # the magnification each q was read at
    p_um: dict[int, float] = field(default_factory=dict)
    passes: int = 0
    looks: int = 0
    history: list[dict[int, float]] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)
    x_per_z: float | None = None  # µm of x-parallax per mm of Z
    measured: list[tuple] = field(default_factory=list)  # (point, q, magnification, actions)


def probe(eyes: Eyes) -> np.ndarray | None:
    """The y-parallax's change per unit of each element at the point the marks are on, by a
    probe turn of each and back, measured at the finding magnification (the probes move the
    detail 4–14 of its pixels). [µm]"""
    base = match(*view(eyes, FIND_MAG), FIND_MAG)
    if base is None:
        return None
    row = np.empty(len(ELEMENTS))
    for k, control in enumerate(ELEMENTS):
        h = PROBE[control]
        eyes.turn(control, h)
        m = match(*view(eyes, FIND_MAG), FIND_MAG, (base.dx_px, base.dy_px), 20.0)
        eyes.turn(control, -h)
        if m is None:
            return None
        row[k] = (m.q_um - base.q_um) / h
    return row


def solve(rec: Orientation, only_mag: int | None = None) -> dict[str, float]:
    """The turns of :data:`ELEMENTS` that null the measured y-parallaxes in least squares
    (minimum norm where fewer than five points are known); ``only_mag``: only the readings
    taken at that magnification. [rad, tan]"""
    pts = [n for n in rec.points if n in rec.q_um and n in rec.jacobian
           and (only_mag is None or rec.mag.get(n) == only_mag)]
    if not pts:
        return {}
    w = np.array([WEIGHT.get(rec.mag.get(n, FIND_MAG), 0.05) for n in pts])
    jac = np.array([rec.jacobian[n] for n in pts]) * w[:, None]
    q = np.array([rec.q_um[n] for n in pts]) * w
    step, *_ = np.linalg.lstsq(jac, -q, rcond=1e-6)
    return dict(zip(ELEMENTS, (float(s) for s in step), strict=True))


#: Turns of κ_п that search for point 1's detail where it is not in the field. [rad]
COMMON_SEARCH = (0.04, -0.04, 0.08, -0.08)
#: The conventional method's order: the point and the element that clears it (κ_п at 1, κ_л at
#: 2, α_л at 4, α_п at 3, ω_п at 5); cycles of it at most; |q| under which a point is left;
#: the largest single turn (rad, tan). [—], [µm], [—]
CLASSIC = ((1, "kappa_right"), (2, "kappa_left"), (4, "k_alpha_left"), (3, "k_alpha_right"),
           (5, "k_omega_right"))
CLASSIC_CYCLES, CLASSIC_DONE_UM, CLASSIC_MAX_TURN = 3, 150.0, 0.05
#: Z's probe steps, tried in turn until one teaches its effect (downwards first: the carriage
#: may start at its upper stop; then upwards, then a longer one down) [mm]; the least change
#: of the x-parallax a probe must make (2 mm of Z changes it by ≈ 730 µm, 15 ×2 pixels, on
#: the C2 exam's SC-1) [µm]; the x-parallax one step of the search by Z moves the detail
#: (under the finding field's half) [µm]; the x-parallax left uncleared (the ×20 search holds
#: ±300 µm) [µm].
Z_PROBES, Z_PROBE_MIN_UM, Z_SEARCH_UM, X_CLEAR_UM = (-2.0, 2.0, -5.0), 50.0, 3500.0, 60.0
#: The x-parallax left uncleared at the measuring magnifications [px]; the largest a ×20
#: reading is taken with (a fused detail read 0–3 px; the matches on something else than the
#: detail that fusing could not clear, 23–53 px: runs of docs/trainer.md) [px].
FUSED_PX, UNFUSED_PX = 3.0, 10.0
#: The step of the marks' positions the page draws the photos at where the read-out is hidden
#: (the X, Y counters' least count, 0.01 mm, as the counters show it) [mm]; looks averaged per
#: ×20 reading; the search radius around the previous look [px].
MARK_STEP_MM, DITHER, DITHER_RADIUS_PX = 0.01, 4, 4.0
#: Steps of the search by Z, in :data:`Z_SEARCH_UM`. [—]
Z_STEPS = (1, -1, 2, -2)
#: The search beyond the finding field (:meth:`Robot.far`): b_y's probe [mm]; the y-parallax
#: one step of b_y adds (under the ×2 search's reach, ±5 mm of photo, so that the steps'
#: reaches overlap) [µm]; the steps, in those units (b_y's range on the SD-3 is ±20 mm) [—].
BY_PROBE_MM, FAR_STEP_UM, FAR_STEPS = 1.0, 4000.0, (1, -1, 2, -2, 3, -3, 4, -4, 5, -5)
#: With the search beyond the field: the largest turn of one conventional clearing (κ up to
#: 0.15 rad clears 8 mm of y-parallax 60 mm from the other photo's centre), and its cycles.
WIDE_MAX_TURN, WIDE_CYCLES = 0.15, 6
#: Halvings of a clearing turn that the stop refused (the knobs stop at tan 3°). [—]
WIDE_STOP_TRIES = 4
#: The search by Z with the search beyond the field, in :data:`Z_SEARCH_UM` (in mountains a
#: detail's x-parallax at another point's Z reaches well over the ±7 mm of :data:`Z_STEPS`:
#: e12, point 5 at 0.7 mm of y-parallax not found by them). [—]
WIDE_Z_STEPS = (1, -1, 2, -2, 3, -3, 4, -4, 5, -5)
#: The reach of a ×2 search beyond the field, on each axis (the steps of Z and b_y move the
#: detail by 70–80 ×2 pixels, so the reaches still overlap). [px]
WIDE_REACH_PX = 85.0


class Robot:
    """The relative orientation from the eyepieces (module docstring). Z, the foot wheel, is
    set to a value (read once from its wheel, then the robot's own settings), and each point's
    fused Z is kept and set again when the robot comes back to it."""

    def __init__(self, eyes: Eyes, tolerance_um: float, points=(1, 2, 3, 4, 5, 6),
                 observer=None, substitutes: dict[int, tuple[float, float]] | None = None,
                 wide: bool = False):
        self.eyes = eyes
        #: Standard point → the offset of its substitute from it on the left photo (x, y up):
        #: the marks go to the point, then on by this offset. [mm]
        self.substitutes = dict(substitutes or {})
        #: Whether a detail outside the finding field is searched for by b_y
        #: (:meth:`far`), and the conventional clearing turns further (:data:`WIDE_MAX_TURN`).
        self.wide = wide
        self.by_base: float | None = None  # b_y as the robot found it (its setting)
        #: The point the marks were last sent to, and whether on to its detail spot.
        self.here: tuple[int, bool] | None = None
        self.q_per_by: float | None = None  # µm of y-parallax seen per mm of b_y
        #: Called with the record after each pass (a benchmark's diagnostics; the robot never
        #: reads what it does).
        self.observer = observer
        self.rec = Orientation(tolerance_um, tuple(points))
        self.z: float | None = None
        self.z_at: dict[int, float] = {}
        self.px_per_xy: np.ndarray | None = None  # ×2 screen px of the left view per mm of X, Y
        self.spot_at: dict[int, tuple[float, float]] = {}  # the X, Y turns to each point's spot

    def learn_xy(self) -> None:
        """How a turn of X and of Y moves the left view (a probe turn of each, once)."""
        eyes = self.eyes
        before = view(eyes, FIND_MAG)[0]
        cols = []
        for axis in ("X", "Y"):
            eyes.turn(axis, XY_PROBE)
            after = view(eyes, FIND_MAG)[0]
            eyes.turn(axis, -XY_PROBE)
            m = match(before, after, FIND_MAG)
            if m is None:
                return
            cols.append([-m.dx_px / XY_PROBE, -m.dy_px / XY_PROBE])
        self.px_per_xy = np.array(cols).T
        self.rec.notes.append(f"px per X, Y: {self.px_per_xy.tolist()}")

    def arrive(self, n: int) -> None:
        """Go to standard point ``n`` (its go-to), and on to its substitute where it has one
        (X and Y turned by the offset, through the learnt effect of X and Y on the view)."""
        self.eyes.go_to(n)
        self.here = (n, False)
        if n not in self.substitutes or self.px_per_xy is None:
            return
        dx_mm, dy_mm = self.substitutes[n]
        px = np.array([dx_mm, -dy_mm]) / (SCREEN_PIXEL_MM / FIND_MAG)
        turns = np.linalg.solve(self.px_per_xy, px)
        for axis, d in zip(("X", "Y"), turns, strict=True):
            self.eyes.turn(axis, round(float(d), 3))

    def set_by(self, value: float) -> float:
        """b_y set (a setting past a stop is refused: the wheel then stays); its value."""
        self.eyes.set("by", round(value, 3))
        return self.eyes.wheel("by")

    def learn_by(self) -> None:
        """How a turn of b_y moves the right view (a probe of :data:`BY_PROBE_MM`, the right
        view before and after matched on itself): the y-parallax it adds a mm."""
        self.by_base = self.eyes.wheel("by")
        before = view(self.eyes, FIND_MAG)[1]
        now = self.set_by(self.by_base + BY_PROBE_MM)
        after = view(self.eyes, FIND_MAG)[1]
        self.set_by(self.by_base)
        m = match(before, after, FIND_MAG)
        if m is None or abs(now - self.by_base) < 0.5 * BY_PROBE_MM:
            self.rec.notes.append(f"b_y probe: {m}, b_y {now}")
            return
        self.q_per_by = m.q_um / (now - self.by_base)
        self.rec.notes.append(f"q per b_y: {self.q_per_by:.0f} µm/mm")

    def far(self, n: int) -> tuple[Match, float] | None:
        """A detail outside the finding field searched for by b_y: b_y set by steps of about
        :data:`FAR_STEP_UM` of y-parallax each way (:data:`FAR_STEPS`), the detail looked for
        at each (and by Z, :meth:`coarse`); the match and the y-parallax the shift of b_y
        added (b_y left where the detail was found; :meth:`by_back` sets it back). [µm]"""
        if self.q_per_by is None or self.by_base is None:
            return None
        for k in FAR_STEPS:
            target = self.by_base + k * FAR_STEP_UM / abs(self.q_per_by)
            now = self.set_by(target)
            if abs(now - target) > 0.015:
                continue  # past b_y's stop: refused
            m = self.coarse(n)
            if m is not None:
                added = (now - self.by_base) * self.q_per_by
                self.rec.notes.append(f"far {n}: b_y {now} ({added:.0f} µm): {m}")
                return m, added
        self.set_by(self.by_base)
        self.rec.notes.append(f"far {n}: not found")
        return None

    def by_back(self) -> None:
        if self.by_base is not None and self.eyes.wheel("by") != self.by_base:
            self.set_by(self.by_base)

    def go_to(self, n: int) -> None:
        """Go to point ``n`` and on to its detail (:func:`textured_spot`), chosen the first
        time from the ×2 view."""
        self.arrive(n)
        self.here = (n, True)
        if self.px_per_xy is None:
            return
        if n not in self.spot_at:
            off = textured_spot(view(self.eyes, FIND_MAG)[0], SPOT_REACH_PX)
            turns = np.linalg.solve(self.px_per_xy, np.array(off)) if any(off) else np.zeros(2)
            self.spot_at[n] = (round(float(turns[0]), 3), round(float(turns[1]), 3))
            self.rec.notes.append(f"spot {n}: {off} px, turns {self.spot_at[n]}")
        for axis, d in zip(("X", "Y"), self.spot_at[n], strict=True):
            if d:
                self.eyes.turn(axis, d)

    def set_z(self, value: float) -> None:
        before = self.z
        self.eyes.set("Z", round(value, 3))
        self.z = self.eyes.wheel("Z")  # at a stop the carriage stays there
        if self.wide and self.here is not None and self.z != before:
            # Z moves the model point the marks are on, and so the left mark off the point
            # (SD-3, e12: 50 mm of Z moved it 28 mm, off the photo at point 2): the marks
            # brought back onto the point at the new Z, as a go-to puts them
            n, spot = self.here
            self.go_to(n) if spot else self.arrive(n)

    def fine_spot(self, n: int, m: Match) -> Match:
        """Where ×20 finds nothing sure at point ``n``'s detail (a striped field, a plain one),
        the marks are moved onto the most detailed place within :data:`FINE_REACH_PX` of the
        ×20 view and looked at there (kept as the point's spot); else the coarser match."""
        if self.px_per_xy is None:
            return m
        mag = FINE_MAGS[0]
        off = textured_spot(view(self.eyes, mag)[0], FINE_REACH_PX)
        if not any(off):
            return m
        turns = np.linalg.solve(self.px_per_xy * (mag / FIND_MAG), np.array(off))
        for axis, d in zip(("X", "Y"), turns, strict=True):
            self.eyes.turn(axis, round(float(d), 4))
        k = mag / m.magnification
        fine = match(*view(self.eyes, mag), mag, (m.dx_px * k, m.dy_px * k), AGREE_PX * k)
        self.rec.notes.append(f"fine spot {n}: {off} px: {fine}")
        if fine is None:
            for axis, d in zip(("X", "Y"), turns, strict=True):
                self.eyes.turn(axis, -round(float(d), 4))
            return m
        x, y = self.spot_at.get(n, (0.0, 0.0))
        self.spot_at[n] = (x + round(float(turns[0]), 4), y + round(float(turns[1]), 4))
        return fine

    def fine(self, n: int, m: Match) -> Match:
        """A match carried to ×6, then ×20, as :func:`refine`, with the x-parallax cleared by Z
        at each magnification before the finer look (a trainee fuses the detail with the foot
        wheel: an x-parallax of a few hundred µm puts the detail outside the ×20 search, and
        the relief inside a template biases a match that is far from fused)."""
        coarser = m
        for mag in (*sorted(FINE_MAGS), None):
            m = self.fuse(m)
            if mag is None:
                break
            if m.magnification < FINE_MAGS[0]:
                coarser = m
            if mag <= m.magnification or not fits((m.dx_px, m.dy_px), m.magnification, mag):
                continue
            k = mag / m.magnification
            images = view(self.eyes, mag)
            finer = match(*images, mag, (m.dx_px * k, m.dy_px * k), AGREE_PX * k)
            if finer is None:
                weak = match(*images, mag, (m.dx_px * k, m.dy_px * k), AGREE_PX * k, strict=False)
                self.rec.notes.append(f"no sure ×{mag} at {n}: {weak}")
                break
            m = finer
        if m.magnification == FINE_MAGS[0] and abs(m.dx_px) > UNFUSED_PX and (
                coarser.magnification < FINE_MAGS[0]):
            m = self.fused_or(n, m, coarser)
        self.z_at[n] = self.z
        return m

    def fused_or(self, n: int, m: Match, coarser: Match) -> Match:
        """A ×20 match ``m`` that fusing did not clear (its x-parallax over
        :data:`UNFUSED_PX`) is not taken as a reading: the detail is looked for fused, near
        ``m``'s y-parallax at no x-parallax (within :data:`UNFUSED_PX`), at the Z it was seen
        at; found, that is the reading; else the coarser reading (``coarser``) is kept. In the
        runs this rule came from, such a match sat 23–53 ×20 pixels off in x, its y offset near
        zero (mostly within 0.6 px) and the same pass after pass while the true q moved by up
        to 8 µm: a match on something other than the detail, its reading 13–21 µm off
        (docs/trainer.md)."""
        mag = m.magnification
        fused = match(*view(self.eyes, mag), mag, (0.0, m.dy_px), UNFUSED_PX)
        self.rec.notes.append(f"unfused ×{mag} at {n}: {m}; fused look: {fused}")
        return coarser if fused is None else fused

    def steady(self, m: Match) -> Match:
        """A ×20 match with its y-parallax averaged over :data:`DITHER` looks, Y turned by a
        :data:`DITHER`-th of :data:`MARK_STEP_MM` (on the photo) between them, and turned back.
        Where the read-out is hidden the page draws each photo at its mark's position in steps
        of the counters' least count, so one look's y-parallax is off by the two marks'
        rounding, up to ±10 µm; over a step evenly sampled each rounding averages out to within
        ``MARK_STEP_MM / (2·DITHER)``."""
        mag = FINE_MAGS[0]
        if self.px_per_xy is None or m.magnification != mag:
            return m
        photo_per_y = abs(self.px_per_xy[1, 1]) * SCREEN_PIXEL_MM / FIND_MAG  # mm per mm of Y
        dy = round(MARK_STEP_MM / DITHER / photo_per_y, 4)
        seen, last, turned = [m], m, 0
        for _ in range(DITHER - 1):
            self.eyes.turn("Y", dy)
            turned += 1
            again = match(*view(self.eyes, mag), mag, (last.dx_px, last.dy_px), DITHER_RADIUS_PX)
            if again is not None:
                seen.append(again)
                last = again
        self.eyes.turn("Y", -round(turned * dy, 4))
        return Match(float(np.mean([s.dx_px for s in seen])),
                     float(np.mean([s.dy_px for s in seen])),
                     min(s.peak for s in seen), min(s.margin for s in seen), mag)

    def fuse(self, m: Match) -> Match:
        """Z set to clear the x-parallax of a match (to :data:`FUSED_PX` pixels of its
        magnification), the detail looked at again at the same magnification; else ``m``,
        with Z set back to where ``m`` was seen."""
        if self.rec.x_per_z is None or abs(m.dx_px) <= FUSED_PX:
            return m
        before = self.z
        self.set_z(self.z - m.p_um / self.rec.x_per_z)
        mag = m.magnification
        again = match(*view(self.eyes, mag), mag, (0.0, m.dy_px), max(AGREE_PX, 0.3 * abs(m.dx_px)))
        if again is None:
            self.set_z(before)  # ``m`` was seen at the Z before: the foot wheel set back
            return m
        return again

    def look(self, predict=None, radius=None, reach=SEARCH_PX) -> Match | None:
        return match(*view(self.eyes, FIND_MAG), FIND_MAG, predict, radius, reach_px=reach)

    def clear_x(self, m: Match) -> Match:
        """Z set to clear the x-parallax of a found detail (up to three settings, the detail
        looked for again after each); the last match, and Z where it was seen."""
        for _ in range(3):
            if self.rec.x_per_z is None or abs(m.p_um) <= X_CLEAR_UM:
                return m
            before = self.z
            self.set_z(self.z - m.p_um / self.rec.x_per_z)
            again = self.look((0.0, m.dy_px), 40.0) or self.look()
            if again is None:
                # ``m`` was seen at the Z before: the foot wheel set back there, so that the
                # point's kept Z and its match agree (a later fusing starts from that Z)
                self.set_z(before)
                return m
            m = again
        return m

    def coarse(self, n: int) -> Match | None:
        """The detail at point ``n`` found at ×2 (a search by Z where not), its x-parallax
        cleared by Z."""
        rec = self.rec
        if n in self.z_at and self.z != self.z_at[n]:
            self.set_z(self.z_at[n])
        if self.wide:
            return self.coarse_wide(n)
        m = self.look()
        if m is None and rec.x_per_z is not None:
            start = self.z
            for k in Z_STEPS:
                self.set_z(start + k * Z_SEARCH_UM / abs(rec.x_per_z))
                m = self.look()
                if m is not None:
                    break
            else:
                self.set_z(start)
        if m is None:
            rec.notes.append(f"coarse {n}: not found")
            return None
        if rec.x_per_z is None:
            m = self.learn_z(m)  # not learnt at point 1: learnt here
        m = self.clear_x(m)
        self.z_at[n] = self.z
        rec.notes.append(f"coarse {n}: {m}")
        return m

    def coarse_wide(self, n: int) -> Match | None:
        """:meth:`coarse` with the search beyond the field: Z set by :data:`WIDE_Z_STEPS`, the
        detail looked for within :data:`WIDE_REACH_PX` (a match farther out was, in e12's
        first runs, a weak false one at the search's edge), and a match taken only where Z
        then fuses it (its x-parallax cleared to :data:`UNFUSED_PX`): a match Z cannot fuse
        is not the detail, and the search goes on."""
        rec = self.rec
        start = self.z
        settings = [0.0]
        if rec.x_per_z is not None:
            settings += [k * Z_SEARCH_UM / abs(rec.x_per_z) for k in WIDE_Z_STEPS]
        for dz in settings:
            if dz:
                self.set_z(start + dz)
            m = self.look(reach=WIDE_REACH_PX)
            if m is None:
                continue
            if rec.x_per_z is None:
                m = self.learn_z(m)
            m = self.clear_x(m)
            if rec.x_per_z is not None and abs(m.dx_px) > UNFUSED_PX:
                rec.notes.append(f"coarse {n}: not fused, refused: {m}")
                continue
            self.z_at[n] = self.z
            rec.notes.append(f"coarse {n}: {m} (Z {self.z})")
            return m
        self.set_z(start)
        rec.notes.append(f"coarse {n}: not found")
        return None

    def clear_with(self, n: int, control: str) -> bool:
        """At point ``n``: the detail found, ``control`` turned by a probe step to learn its
        effect on the y-parallax, then turned to clear it (a step of the conventional method,
        by the eye)."""
        self.arrive(n)
        m = self.coarse(n)
        added = 0.0  # the y-parallax a shifted b_y adds to what is seen [µm]
        if m is None and self.wide:
            found = self.far(n)
            if found is not None:
                m, added = found
        if m is None:
            return False
        if abs(m.q_um - added) < CLASSIC_DONE_UM:
            self.by_back()
            return True
        self.eyes.turn(control, PROBE[control])
        moved = self.look((m.dx_px, m.dy_px), 40.0)
        if moved is None or abs(moved.q_um - m.q_um) < 20.0:
            self.eyes.turn(control, -PROBE[control])
            self.by_back()
            return False
        per = (moved.q_um - m.q_um) / PROBE[control]
        most = WIDE_MAX_TURN if self.wide else CLASSIC_MAX_TURN
        d = float(np.clip(-(moved.q_um - added) / per, -most, most))
        was = self.eyes.wheel(control) if self.wide else None
        self.eyes.turn(control, d)
        for _ in range(WIDE_STOP_TRIES if self.wide else 0):
            if self.eyes.wheel(control) != was:
                break
            d /= 2  # a turn past the stop is refused: a shorter one
            self.eyes.turn(control, d)
        self.by_back()
        self.rec.notes.append(f"classic {n} {control}: q {moved.q_um - added:.0f} µm, "
                              f"turned {d:.5f}")
        return True

    def learn_z(self, m: Match) -> Match:
        """Z's effect on the x-parallax learnt from a found detail ``m``: Z set by each of
        :data:`Z_PROBES` in turn from where it is (a setting past a stop leaves it there and is
        skipped), the detail looked for near ``m``, then anywhere, until one changes the
        x-parallax by more than :data:`Z_PROBE_MIN_UM`; Z stays at the setting that taught it
        (the detail as seen there returned), else goes back (``m`` returned)."""
        z0 = self.z
        for dz in Z_PROBES:
            self.set_z(z0 + dz)
            if self.z == z0:
                continue
            moved = self.look((m.dx_px, m.dy_px), 40.0) or self.look()
            if moved is not None and abs(moved.p_um - m.p_um) > Z_PROBE_MIN_UM:
                self.rec.x_per_z = (moved.p_um - m.p_um) / (self.z - z0)
                self.rec.notes.append(f"x per Z: {self.rec.x_per_z} µm/mm (probe {dz:+} mm)")
                return moved
            self.rec.notes.append(f"Z probe {dz:+} mm: {moved}")
            self.set_z(z0)
        self.rec.notes.append("x per Z: None")
        return m

    def start(self) -> None:
        """Point 1 found (a search by turns of κ_п where not), Z's effect on the x-parallax
        learnt there; then cycles of the conventional method's element-by-element clearing (by
        the eye, each element's effect learnt by a probe turn) until every detail is found near
        the mark."""
        n = self.rec.points[0]
        self.arrive(n)
        self.z = self.eyes.wheel("Z")
        if self.wide or self.substitutes:
            # the effects of X, Y (for the substitutes) and of b_y (for the search beyond
            # the field) learnt first: each from one view matched on itself
            self.learn_xy()
            if self.wide:
                self.learn_by()
        m = self.look()
        for d in COMMON_SEARCH:
            if m is not None:
                break
            self.eyes.turn("kappa_right", d)
            m = self.look()
            if m is None:
                self.eyes.turn("kappa_right", -d)
        if m is None and self.wide:
            found = self.far(n)
            m = None if found is None else found[0]
        if m is None:
            return
        self.learn_z(m)
        self.by_back()
        for _ in range(WIDE_CYCLES if self.wide else CLASSIC_CYCLES):
            ok = [self.clear_with(p, c) for p, c in CLASSIC if p in self.rec.points]
            if all(ok):
                break
        self.eyes.go_to(n)
        if self.px_per_xy is None:
            self.learn_xy()

    def predict(self, q_um: dict[int, float], p_um: dict[int, float],
                step: dict[str, float]) -> dict[int, tuple[float, float]]:
        """The parallaxes (x, y) expected at the points after ``step`` from ``q_um``, ``p_um``."""
        out = {}
        for n in q_um:
            if n in self.rec.jacobian and step:
                dq = float(self.rec.jacobian[n] @ np.array([step[c] for c in ELEMENTS]))
                out[n] = (p_um[n], q_um[n] + dq)
        return out

    def turn_all(self, step: dict[str, float], sign: float = 1.0) -> None:
        """The elements turned by ``sign`` × ``step``."""
        for control, d in step.items():
            if abs(d) > 1e-7:
                self.eyes.turn(control, sign * d)

    def read(self, n: int, predicted: dict[int, tuple[float, float]]) -> Match | None:
        """Point ``n`` measured (near its predicted parallaxes where there are some), its
        Jacobian row probed where it has none."""
        rec, eyes = self.rec, self.eyes
        self.go_to(n)
        m = None
        if n in predicted and n in self.z_at:
            if self.z != self.z_at[n]:
                self.set_z(self.z_at[n])
            m = measure(eyes, predicted[n])
            if m is not None and (m.magnification == FIND_MAG or (
                    m.magnification == FINE_MAGS[0] and abs(m.dx_px) > UNFUSED_PX)):
                m = None  # found only at ×2, or at ×20 not fused: looked for from ×2 again
            if m is not None:
                if n not in rec.jacobian:
                    self.probe_row(n)
                m = self.fine(n, m)
        if m is None:
            m = self.coarse(n)
            if m is None:
                return None
            if n not in rec.jacobian:
                self.probe_row(n)
            m = self.fine(n, m)
        if m.magnification != FINE_MAGS[0]:
            m = self.fine_spot(n, m)
        if (m.magnification == FIND_MAG and rec.x_per_z is not None
                and abs(m.dx_px) > UNFUSED_PX):
            # a ×2 match whose x-parallax Z could not clear (each fusing look lost it): not
            # taken as a reading, as an unfused ×20 match is not (:meth:`fused_or`)
            rec.notes.append(f"unfused ×{FIND_MAG} at {n}: {m}: not read")
            return None
        return self.steady(m)

    def probe_row(self, n: int) -> None:
        row = probe(self.eyes)
        self.rec.notes.append(f"probe {n}: {row}")
        if row is not None:
            self.rec.jacobian[n] = row

    def run(self) -> Orientation:
        rec, eyes = self.rec, self.eyes
        self.start()
        predicted: dict[int, tuple[float, float]] = {}
        last_step: dict[str, float] = {}
        last_q: dict[int, float] = {}
        last_p: dict[int, float] = {}
        last_mag: dict[int, int] = {}
        halvings = retreats = 0
        while rec.passes < PASSES:
            rec.passes += 1
            rec.q_um.clear()
            rec.mag.clear()
            for n in rec.points:
                m = self.read(n, predicted)
                if m is None:
                    continue
                rec.notes.append(f"measure {n}: {m}")
                rec.q_um[n], rec.p_um[n], rec.mag[n] = m.q_um, m.p_um, m.magnification
                rec.measured.append((n, m.q_um, m.magnification, getattr(eyes, "sent", None)))
            rec.history.append(dict(rec.q_um))
            if self.observer is not None:
                self.observer(rec)
            found = set(rec.q_um)
            lost = sorted(set(last_q) - found)
            worse = _worse(rec.q_um, rec.mag, last_q, last_mag)
            last_pass = rec.passes >= PASSES
            if last_step and lost and (retreats < HALVINGS or last_pass):
                # the last step lost a point: turned back whole, to where every point was
                # found; measured again there, the lost points' rows probed again
                retreats += 1
                self.turn_all(last_step, -1.0)
                for n in lost:
                    rec.jacobian.pop(n, None)
                rec.notes.append(f"step turned back (lost {lost})")
                rec.q_um, rec.p_um, rec.mag = dict(last_q), dict(last_p), dict(last_mag)
                last_step = {}
                predicted = {n: (last_p[n], last_q[n]) for n in last_q}
                continue
            if last_step and worse and last_pass:
                # no pass is left to check a half: turned back whole, to the state measured
                self.turn_all(last_step, -1.0)
                rec.notes.append("last step turned back (worse)")
                rec.q_um, rec.p_um, rec.mag = dict(last_q), dict(last_p), dict(last_mag)
                break
            if last_step and worse and halvings < HALVINGS:
                # the last step made the parallaxes worse: half of it turned back (the wheels
                # turned back by the amounts they were turned), measured again
                halvings += 1
                last_step = {c: d / 2 for c, d in last_step.items()}
                self.turn_all(last_step, -1.0)
                rec.notes.append(f"step halved (worse {worse})")
                predicted = self.predict(last_q, last_p, last_step)
                continue
            halvings = 0
            sure = [n for n in rec.q_um if rec.mag[n] == FINE_MAGS[0]]
            done = len(sure) == len(rec.points) and all(
                abs(rec.q_um[n]) < DONE_SHARE * rec.tolerance_um for n in sure)
            if done or last_pass:
                # the last pass measures the step before it, and none is taken after it
                break
            near = (len(found) == len(rec.points) and len(sure) >= NEAR_FINE
                    and max(abs(rec.q_um[n]) for n in sure) < NEAR_UM)
            if near:
                # near the solution the readings' scatter is most of what is left: a share
                # of each step averages it over the passes; the step is solved from the ×20
                # readings alone
                step = {c: NEAR_SHARE * d for c, d in solve(rec, FINE_MAGS[0]).items()}
            else:
                step = solve(rec)
                if len(found) < len(rec.points):
                    # a point not found: five points fix the five elements with no check,
                    # so only a share of the step is taken
                    step = {c: PARTIAL_SHARE * d for c, d in step.items()}
            if last_step:
                retreats = 0  # the step before was measured and kept
            if retreats:
                # after a step that lost a point: a shorter one
                step = {c: LOST_SHARE**retreats * d for c, d in step.items()}
            self.turn_all(step)
            last_step, last_q = step, dict(rec.q_um)
            last_p, last_mag = dict(rec.p_um), dict(rec.mag)
            predicted = self.predict(last_q, last_p, step)
        return rec


def _worse(q_um: dict[int, float], mag: dict[int, int], last_q: dict[int, float],
           last_mag: dict[int, int]) -> bool:
    """Whether the largest |q| of the points read both times (at ×20 both times where
    :data:`NEAR_FINE` points were) rose above :data:`WORSE_FACTOR` × its value before plus
    :data:`WORSE_UM`."""
    common = set(q_um) & set(last_q)
    fine = {n for n in common if mag.get(n) == last_mag.get(n) == FINE_MAGS[0]}
    if len(fine) >= NEAR_FINE:
        common = fine
    if not common:
        return False
    return max(abs(q_um[n]) for n in common) > (
        WORSE_FACTOR * max(abs(last_q[n]) for n in common) + WORSE_UM)


#: How far a substitute for an unusable standard point is put from it, towards the middle
#: of the other points (the grade takes one within 0.2·c of the point, 14 mm for c = 70 mm;
#: the ×2 field's half is 6.4 mm). [mm]
SUBSTITUTE_MM = 10.0


def substitute_offset(points: dict[int, tuple[float, float]], n: int) -> tuple[float, float]:
    """Where to look instead of the unusable standard point ``n`` (``points``: the standard
    points on the left photo, as the overview draws them): :data:`SUBSTITUTE_MM` from it
    towards the mean of the others, as the offset from it (x, y up). [mm]"""
    here = np.array(points[n], float)
    rest = np.mean([xy for k, xy in points.items() if k != n], axis=0)
    way = (rest - here) / np.linalg.norm(rest - here)
    return float(round(way[0] * SUBSTITUTE_MM, 3)), float(round(way[1] * SUBSTITUTE_MM, 3))


def relative_orientation(eyes: Eyes, tolerance_um: float, points=(1, 2, 3, 4, 5, 6),
                         observer=None, substitutes=None, wide: bool = False,
                         notes: list | None = None) -> Orientation:
    """Clear the y-parallax at the standard ``points`` by least squares on the measured
    parallaxes (module docstring); returns the record (the last measured q at each point).
    ``observer`` (diagnostics only) is called with the record after each pass; ``notes``
    (diagnostics only) is the list the robot's notes are appended to as they are made.
    ``substitutes``: standard point → the offset of its substitute on the left photo (mm,
    :func:`substitute_offset`); ``wide``: search beyond the finding field by b_y."""
    robot = Robot(eyes, tolerance_um, points, observer, substitutes, wide)
    if notes is not None:
        robot.rec.notes = notes
    return robot.run()
