"""Verdicts of the verification table decided from the numbers (pure, no state).

Vocabulary (:data:`VERDICTS`): ``reproduces``, ``inherits error of (x.y)``, ``misprint`` (the
note gives the corrected value), ``convention`` (the note names both readings),
``not reproducible`` (the note says what was tried). The last two are the only hand-written
verdicts: a rule cannot tell a convention from an error, nor list the readings tried.

Tolerance rule
--------------
* A number printed with d decimals *agrees* with a value v when v rounded to d decimals or v
  truncated to d decimals equals it; the note says which of the two (both are checked, and both
  results are printed).
* A printed formula evaluated at the geometry, and two formula values, *agree* when their relative
  difference is ≤ :data:`REL_TOL` (0.5 %: the book's coefficients carry 2–3 significant digits).

Rule, with ``ref`` the book's arithmetic from its printed intermediates (``from_printed_inputs``)
when the row has it, else the book's formula evaluated exactly (``book``):

1. printed value does not agree with ``ref`` → ``not reproducible`` if the row says so (readings
   tried in its note), else ``misprint``, corrected value ``ref``;
2. no printed value (a user geometry, or the book prints none) → ``book`` against ``rigorous``;
3. ``ref`` (or ``book``) agrees with ``rigorous`` → ``reproduces``; else the row's hand-marked
   ``convention``, else ``inherits error of`` its upstream equation, else ``misprint``, corrected
   value ``rigorous``.
"""

from __future__ import annotations

import math

__all__ = ["REL_TOL", "VERDICTS", "agree", "decide", "is_verdict", "printed_agreement"]

VERDICTS = ("reproduces", "inherits error of", "misprint", "convention", "not reproducible")
#: Relative tolerance for two formula values (the book's coefficients carry 2–3 digits).
REL_TOL = 5e-3
HAND = ("convention", "not reproducible")


def is_verdict(v: str) -> bool:
    """True for a verdict of the vocabulary (``inherits error of (x.y)`` with its equation)."""
    return v in VERDICTS or (v.startswith("inherits error of (") and v.endswith(")"))


def agree(x: float, y: float, rel: float = REL_TOL) -> bool:
    """Formula values equal within the relative tolerance."""
    return abs(x - y) <= rel * max(abs(x), abs(y))


def printed_agreement(printed: float, value: float, digits: int) -> tuple[str | None, str]:
    """How ``value`` gives the ``printed`` number of ``digits`` decimals.

    Returns ("rounded" | "truncated" | None, text naming both results).

    >>> printed_agreement(0.96, 0.9650, 2)
    ('truncated', 'rounds to 0.97, truncates to 0.96')
    """
    scale = 10**digits
    rounded = math.floor(value * scale + 0.5) / scale  # half up, not to even
    truncated = math.floor(value * scale + 1e-9) / scale
    text = f"rounds to {rounded:.{digits}f}, truncates to {truncated:.{digits}f}"
    if math.isclose(rounded, printed, abs_tol=1e-12):
        return "rounded", text
    if math.isclose(truncated, printed, abs_tol=1e-12):
        return "truncated", text
    return None, text


def _matches(printed: float, value: float, digits: int | None) -> tuple[bool, str]:
    if digits is None:
        return agree(printed, value), f"{value:.5g}"
    how, text = printed_agreement(printed, value, digits)
    return how is not None, f"{value:.4f} ({text}{': ' + how if how else ''})"


def decide(
    printed: float | None,
    from_printed_inputs: float | None,
    book: float,
    rigorous: float,
    *,
    digits: int | None = None,
    upstream: str | None = None,
    hand: str | None = None,
) -> tuple[str, str]:
    """Verdict and the note of what was compared (the rule of the module docstring).

    ``digits``: decimals of a printed number (None: ``printed`` is a printed formula evaluated at
    the geometry). ``hand``: ``convention`` or ``not reproducible`` from the row, else None.

    >>> decide(1.11, 1.1420, 1.1424, 1.1298, digits=2)[0]
    'misprint'
    >>> decide(1.26, 1.2620, 1.2604, 1.2143, digits=2, upstream="(6.37)")[0]
    'inherits error of (6.37)'
    """
    if hand is not None and hand not in HAND:
        raise ValueError(f"hand verdict: expected one of {HAND}, found {hand!r}")
    label, ref = (
        ("from printed inputs", from_printed_inputs)
        if from_printed_inputs is not None
        else ("book formula", book)
    )
    parts = []
    if printed is not None:
        ok, text = _matches(printed, ref, digits)
        parts.append(f"printed {printed:.5g} vs {label} {text}")
        if not ok:
            if hand == "not reproducible":
                return hand, "; ".join(parts)
            return "misprint", "; ".join(parts) + f"; corrected value {ref:.5g}"
    else:
        ref, label = book, "book formula"
        parts.append("no printed value compared")
    same = agree(ref, rigorous) or (printed is not None and _matches(printed, rigorous, digits)[0])
    parts.append(f"{label} {ref:.5g} vs rigorous {rigorous:.5g}")
    if same:
        return "reproduces", "; ".join(parts)
    if hand == "convention":
        return hand, "; ".join(parts)
    if upstream:
        return f"inherits error of {upstream}", "; ".join(parts)
    return "misprint", "; ".join(parts) + f"; corrected value {rigorous:.5g}"
