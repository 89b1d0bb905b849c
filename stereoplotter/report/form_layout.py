"""The setup form's document and drawing primitives: the A4 page with its fonts, tables, and text
labels placed so that none overlaps another (the drawing's point and corner labels).

fpdf2 (a document library: real text that can be searched and extracted, vector drawing,
embedded TrueType subsets), through its low-level calls for the tables and paragraphs: their
lines are broken here by the font's advance widths, remembered per string, and drawn with
``text`` and ``line`` — fpdf2's own ``table`` and ``multi_cell`` measure every fragment again at
each character (the cost: ``bench_job_sheets.py`` in ``benchmarks/README.md``). The fonts are
parsed once per process and each font subset compiled once per set of glyphs
(:meth:`Form.output`). A document of many forms takes each form's pages as drawn for the form
alone, their text re-encoded to its own font subsets and their footers numbered in it
(:meth:`Form.append_pages`): no form is laid out twice. The Cyrillic and Greek symbols need a
Unicode font: DejaVu Sans, the font that ships inside matplotlib (``mpl-data/fonts/ttf``), found
without importing matplotlib, so no system font is read.
"""

from __future__ import annotations

import copy
import datetime as _dt
import functools
import importlib.util
import io
import re
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import fpdf.output
from fontTools import subset as ftsubset
from fontTools import ttLib
from fpdf import FPDF
from fpdf.enums import TextMode
from fpdf.fonts import SubsetMap, TTFFont
from fpdf.util import escape_parens

from stereoplotter.glossary import localize

__all__ = [
    "FONT",
    "Form",
    "LabelPlacer",
    "font_path",
    "forget_layout",
    "heading",
    "literal",
    "localized_text",
    "paragraph",
    "plain",
    "rich_runs",
    "table",
    "text_width",
    "wrap_lines",
]

FONT = "DejaVu"
MARGIN_LEFT, MARGIN_RIGHT, MARGIN_TOP, MARGIN_BOTTOM = 20.0, 15.0, 12.0, 16.0
_PT = 0.3528  # mm per point


def font_path(style: str = "") -> str:
    """The DejaVu font file matplotlib ships, found without importing matplotlib (its package
    folder from the import system's spec: only ``plotting`` imports matplotlib)."""
    name = {"": "DejaVuSans.ttf", "B": "DejaVuSans-Bold.ttf"}[style]
    spec = importlib.util.find_spec("matplotlib")
    if spec is None or not spec.submodule_search_locations:  # pragma: no cover - a dependency
        raise RuntimeError("matplotlib (a dependency) is not installed: no DejaVu font")
    folder = Path(next(iter(spec.submodule_search_locations)))
    return str(folder / "mpl-data" / "fonts" / "ttf" / name)


#: Advance widths of texts, by (font file, text, size): a pure function of the font file, kept
#: for the process (fpdf2 sums the glyph widths of every fragment again at each line break);
#: emptied when it holds :data:`_WIDTHS_MAX` entries (a memory bound for a job of many forms).
_WIDTHS: dict[tuple[str, str, float], tuple[int, float]] = {}
_WIDTHS_MAX = 200_000


class _RememberedWidths(TTFFont):
    """A TrueType font whose text widths are computed once per process (the same numbers as
    :meth:`TTFFont.get_text_width`, so the same bytes)."""

    __slots__ = ()

    def get_text_width(
        self, text: str, font_size_pt: float, text_shaping_params: dict[str, Any] | None
    ) -> tuple[int, float]:
        if text_shaping_params:  # pragma: no cover - the forms do not shape text
            return super().get_text_width(text, font_size_pt, text_shaping_params)
        key = (str(self.ttffile), text, font_size_pt)
        width = _WIDTHS.get(key)
        if width is None:
            if len(_WIDTHS) >= _WIDTHS_MAX:
                _WIDTHS.clear()
            width = _WIDTHS[key] = super().get_text_width(text, font_size_pt, None)
        elif font_size_pt > self.biggest_size_pt:
            self.biggest_size_pt = font_size_pt
        return width


#: The two fonts as parsed once per process (metrics, character map, glyph ids), by style;
#: each document gets a copy of its own (see :func:`_document_font`).
_PARSED: dict[str, _RememberedWidths] = {}
#: The font files' bytes, by path (each document's font file object reads from them).
_FONT_BYTES: dict[str, bytes] = {}


def _document_font(style: str, index: int) -> _RememberedWidths:
    """A font for one document: the font parsed once per process (``FPDF.add_font`` reads the
    character map and every glyph's width, ≈ 0.25 s a font), with what a document changes made
    its own: its index, the glyphs it uses (the subset) and a fresh font file object (fpdf2
    subsets that object in place when the document is output)."""
    parsed = _PARSED.get(style)
    if parsed is None:
        loader = FPDF()
        loader.add_font(FONT, style, font_path(style))
        parsed = loader.fonts[f"{FONT.lower()}{style}"]
        parsed.ttfont.close()  # its file stays open otherwise; each document has its own copy
        parsed.__class__ = _RememberedWidths  # same layout (slots): only the width lookup changes
        _PARSED[style] = parsed
    font = copy.copy(parsed)
    font.i = index
    data = _FONT_BYTES.get(parsed.ttffile)
    if data is None:  # read whole once: a lazily read file object would stay open until collected
        data = _FONT_BYTES[parsed.ttffile] = Path(parsed.ttffile).read_bytes()
    font.ttfont = _SavedFont(io.BytesIO(data), recalcTimestamp=False, lazy=True)
    font.missing_glyphs = []
    font.biggest_size_pt = 0
    font._hbfont = None
    font.subset = SubsetMap(font)
    return font


class _SavedFont(ttLib.TTFont):
    """A font file object that compiles itself once: its subset is only ever made again to
    the same glyphs (:meth:`Form.output`), so its bytes do not change after the first save."""

    saved: bytes | None = None
    #: The glyph names it is subset to (set once it is, :meth:`Form.output`).
    subset_to: frozenset[str] | None = None

    def save(self, file: Any, reorderTables: bool | None = True) -> None:
        if self.saved is None:
            buffer = io.BytesIO()
            super().save(buffer, reorderTables)
            self.saved = buffer.getvalue()
        file.write(self.saved)


class _Subsetter(ftsubset.Subsetter):  # type: ignore[misc]
    """fontTools' subsetter as fpdf2 runs it on every font of a document it outputs, except on
    a font file object already subset to the glyphs asked for (:data:`_SUBSETS`,
    ``subset_to``): subsetting it again to them gives the same font, byte for byte, and was
    a twelfth of a form's time."""

    def subset(self, font: Any) -> None:
        done = getattr(font, "subset_to", None)
        asked = self.glyph_names_requested
        if done is not None and done == asked and not (
            self.unicodes_requested or self.glyph_ids_requested
        ):
            return
        super().subset(font)


class _SubsetModule:
    """:mod:`fontTools.subset` as fpdf2's output module sees it: its :class:`_Subsetter`."""

    Subsetter = _Subsetter

    def __getattr__(self, name: str) -> Any:
        return getattr(ftsubset, name)


fpdf.output.ftsubset = _SubsetModule()  # type: ignore[attr-defined]


#: The font file objects as subset by an output, by (font file, glyph names): the next document
#: with the same glyphs starts from one (:meth:`Form.output`); at most :data:`_SUBSETS_MAX`.
_SUBSETS: dict[tuple[str, frozenset[str]], _SavedFont] = {}
_SUBSETS_MAX = 32


class Form(FPDF):
    """A4 portrait with the margins, fonts and the running footer of the forms.

    The creation date is the job's date, never the clock, and no producer version is written:
    the same inputs give the same bytes.
    """

    def __init__(self, date: str, page_word: str = "page", lang: str = "en") -> None:
        super().__init__(orientation="P", unit="mm", format="A4")
        self.lang = lang
        for style in ("", "B"):
            self.fonts[f"{FONT.lower()}{style}"] = _document_font(style, len(self.fonts) + 1)
        self.set_margins(MARGIN_LEFT, MARGIN_TOP, MARGIN_RIGHT)
        self.set_auto_page_break(True, MARGIN_BOTTOM)
        day = _dt.datetime.strptime(date, "%Y-%m-%d").replace(tzinfo=_dt.UTC)
        self.set_creation_date(day)
        self.set_producer("stereoplotter")
        self.set_creator("stereoplotter")
        self.footer_text = ""
        self.page_word = page_word
        #: Per page, its body (the content before its footer) and the drawing state after it
        #: (:meth:`append_pages` copies the body and draws the footer again).
        self.page_ends: dict[int, tuple[bytes, dict[str, Any]]] = {}
        #: Per font index, each character's code in this document's subset (:meth:`text`).
        self._codes: dict[int, dict[str, str]] = {}
        #: Per font index, each text as its "(…) Tj" operand in this document.
        self._encoded: dict[int, dict[str, str]] = {}
        #: (font index, an operand's bytes between its parentheses) → the text it encodes
        #: (:meth:`text`), for a document that takes this one's pages (:meth:`append_pages`).
        self.operand_texts: dict[tuple[int, bytes], str] = {}
        #: (font index, text) → its "(…) Tj" operand in this document, as re-encoded from the
        #: pages of any form it took (:meth:`_reencoded`).
        self._taken_texts: dict[tuple[int, str], bytes] = {}

    def text(self, x: float, y: float, text: str = "") -> None:
        """fpdf2's ``text`` for what the forms draw (filled text, no underline, a TrueType
        font): the same bytes, each text encoded once per document (fpdf2 maps every character
        through its subset again at every call)."""
        font = self.current_font
        if (not self.page or not self.font_family or self.buffer or self.underline
                or self.strikethrough or self.text_mode != TextMode.FILL
                or self._record_text_quad_points or not isinstance(font, TTFFont)
                or font.is_symbol or font.color_font):  # fmt: skip
            super().text(x, y, text)  # pragma: no cover - the forms draw none of these
            return
        if not self.current_font_is_set_on_page:
            self._out(self._set_font_for_page(font, self.font_size_pt))
        encoded = self._encoded.setdefault(font.i, {}).get(text)
        if encoded is None:
            codes = self._codes.setdefault(font.i, {})
            mapped = []
            for char in text:
                code = codes.get(char)
                if code is None:
                    picked = font.subset.pick(ord(char))
                    code = codes[char] = "" if picked is None else chr(picked)
                mapped.append(code)
            encoded = self._encoded[font.i][text] = _operand("".join(mapped))
            self.operand_texts[(font.i, encoded[1:-4].encode("latin-1"))] = text
        line = f"BT {x * self.k:.2f} {(self.h - y) * self.k:.2f} Td {encoded} ET"
        if self.fill_color != self.text_color:
            line = f"q {self.text_color.serialize().lower()} {line} Q"
        self._out(line)

    def rich_text(self, x: float, y: float, text: str) -> float:
        """Draw ``text`` (a form text: :func:`rich_runs`) with its baseline at (x, y) in the
        current font, each subscript smaller and lowered; returns the width drawn (mm)."""
        size, style = self.font_size_pt, self.font_style
        # only the size changes within a text (the forms' one family, this style; no underline
        # or strike-through): fpdf2's set_font_size, what its set_font does then
        for run, sub in _runs(text):
            run_size = size * _SUB if sub else size
            if run_size != self.font_size_pt:
                self.set_font_size(run_size)
            self.text(x, y + (_SUB_DROP * size * _PT if sub else 0.0), run)
            x += _plain_width(self, run, style, run_size)
        if self.font_size_pt != size:
            self.set_font_size(size)
        return x

    def append_pages(self, source: Form) -> None:
        """Append the pages of ``source`` (a :class:`Form` already output) as drawn there: each
        page's body copied, its text re-encoded to this document's font subsets, its footer
        drawn again here (with this document's page number). No page is laid out again; the
        pages look as in ``source`` (the PDF page starts from the default graphics state, so a
        page's content does not depend on the page before it)."""
        codes: dict[int, dict[int, int]] = {}
        operands: dict[tuple[int, bytes], bytes] = {}
        for number in range(1, source.page + 1):
            body, state = source.page_ends[number]
            if self.page > 0:
                self._render_footer()
            label = None if self.page == 0 else self.pages[self.page].get_page_label()
            self._beginpage("", "", False, self.page_duration, self.page_transition)
            self.pages[self.page].set_page_label(label, None)
            self.pages[self.page].contents.extend(self._reencoded(body, source, codes, operands))
            for (page, kind), names in list(source._resource_catalog.resources_per_page.items()):
                if page == number:
                    self._resource_catalog.resources_per_page[(self.page, kind)].update(names)
            self._set_state(state)

    def _reencoded(
        self,
        body: bytes,
        source: Form,
        codes: dict[int, dict[int, int]],
        operands: dict[tuple[int, bytes], bytes],
    ) -> bytes:
        """``body`` of a page of ``source`` with every "(…) Tj" operand mapped from the
        source's subset codes to this document's (the font of each from the "Tf" before it);
        ``codes`` and ``operands`` remember the mapping for the pages of one source."""
        own = {f.i: f for f in self.fonts.values()}
        theirs = {f.i: f for f in source.fonts.values()}
        current = [0]
        opening = [0]  # the "(" inside the operands (each one's own, escaped ones in it)

        def swap(match: re.Match[bytes]) -> bytes:
            if match.group(1) is not None:
                current[0] = int(match.group(1))
                return match.group(0)
            index = current[0]
            opening[0] += 1 + match.group(2).count(b"(")
            done = operands.get((index, match.group(2)))
            if done is not None:
                return done
            table = codes.get(index)
            if table is None:  # at the font's first text of the source, as each page comes
                target = own[index].subset
                table = codes[index] = {
                    code: target.pick_glyph(glyph)
                    for glyph, code in theirs[index].subset.items()
                    if glyph is not None
                }
            # a text an earlier form drew too has its operand here already: a glyph's code in
            # this document does not change once given
            text = source.operand_texts.get((index, match.group(2)))
            done = None if text is None else self._taken_texts.get((index, text))
            if done is None:
                codes_text = _UNESCAPE.sub(_unescape, match.group(2)).decode("utf-16-be")
                done = _operand("".join(chr(table[ord(c)]) for c in codes_text)).encode("latin-1")
                if text is not None:
                    self._taken_texts[(index, text)] = done
            operands[(index, match.group(2))] = done
            return done

        out = _TOKENS.sub(swap, body)
        # every "(" of the page inside an operand: no text other than "(…) Tj" (counted, not
        # found by a second pass of the expression over the page)
        if body.count(b"(") != opening[0]:  # pragma: no cover - text not written by the forms
            raise RuntimeError("a page holds text other than (…) Tj operands: not copied")
        return out

    def _state(self) -> dict[str, Any]:
        state = {name: getattr(self, name) for name in _STATE}
        state["current_font"] = None if self.current_font is None else self.current_font.fontkey
        return state

    def _set_state(self, state: dict[str, Any]) -> None:
        for name, value in state.items():
            setattr(self, name, value)
        if state["current_font"] is not None:
            self.current_font = self.fonts[state["current_font"]]

    def output(self, *args: Any, **kwargs: Any) -> Any:
        """The document's bytes, with each font's subset taken from :data:`_SUBSETS` when an
        earlier document of this process used the same glyphs (fpdf2 subsets the font file
        object in place; subsetting that result again to the same glyphs is the same font,
        byte for byte, in a fraction of the time), and remembered for the next document."""
        used = []
        for font in self.fonts.values():
            if not isinstance(font, TTFFont):  # pragma: no cover - the forms embed TrueType only
                continue
            key = (str(font.ttffile), frozenset(font.subset.get_all_glyph_names()))
            remembered = _SUBSETS.pop(key, None)  # taken out while in use (another thread misses)
            if remembered is not None:
                font.ttfont.close()
                font.ttfont = remembered
            used.append((key, font))
        data = super().output(*args, **kwargs)
        for key, font in used:
            if len(_SUBSETS) >= _SUBSETS_MAX:
                for ttfont in _SUBSETS.values():
                    ttfont.close()
                _SUBSETS.clear()
            font.ttfont.subset_to = key[1]
            earlier = _SUBSETS.get(key)  # another thread's document of the same glyphs
            if earlier is not None and earlier is not font.ttfont:
                earlier.close()
            _SUBSETS[key] = font.ttfont
        return data

    def close_fonts(self) -> None:
        """Close the font files of a document that is never output (a trial layout)."""
        for font in self.fonts.values():
            close = getattr(font, "close", None)
            if close is not None:
                close()

    def footer(self) -> None:
        self.page_ends[self.page] = (bytes(self.pages[self.page].contents), self._state())
        self.set_y(-MARGIN_BOTTOM + 5)
        self.set_font(FONT, "", 8)
        self.set_text_color(60)
        self.rich_text(self.l_margin, self.get_y() + 2.0 + 0.3 * self.font_size,
                       localized(self, self.footer_text))  # fmt: skip
        self.set_x(self.l_margin)
        self.cell(0, 4, f"{self.page_word} {self.page_no()}", align="R")
        self.set_text_color(0)


#: The drawing state a page's footer starts from (:meth:`Form.append_pages`).
_STATE = (
    "font_family", "font_style", "font_size_pt", "current_font", "current_font_is_set_on_page",
    "line_width", "draw_color", "fill_color", "text_color", "underline", "strikethrough",
    "font_stretching", "char_spacing", "dash_pattern", "footer_text",
)  # fmt: skip
#: A content stream's font selections and text operands (the forms write only "(…) Tj").
_TOKENS = re.compile(rb"/F(\d+) [-+]?[0-9.]+ Tf|\(((?:\\.|[^\\)])*)\) Tj", re.S)
_UNESCAPE = re.compile(rb"\\(.)", re.S)


def _unescape(match: re.Match[bytes]) -> bytes:
    return b"\r" if match.group(1) == b"r" else match.group(1)


def _operand(codes: str) -> str:
    """A "(…) Tj" operand of subset codes, as fpdf2's ``TTFFont.encode_text`` writes it."""
    return f"({escape_parens(codes.encode('utf-16-be').decode('latin-1'))}) Tj"


#: A subscript's size (× the text's) and its drop below the baseline (× the text's size).
_SUB, _SUB_DROP = 0.72, 0.28
#: Where user text (a job's name, a camera, an id) begins and ends inside a form text: drawn
#: as written, no subscript and no localisation (:func:`literal`).
_OPEN, _CLOSE = "\x1e", "\x1f"
_LITERAL = re.compile(f"{_OPEN}([^{_CLOSE}]*){_CLOSE}?")
#: A subscript: after "_" that follows a symbol's character, up to a space, a bracket, an
#: operator, or a comma followed by a space ("O_Y3,л", "θ_α, θ_ω", "f_пр/f′", "M_map").
_SUBSCRIPT = re.compile(r"(?<=[^\s_])_((?:[^\s()=;·/+−:,_\u2009]|,(?=[^\s,]))+)")


def plain(text: str) -> str:
    """A form text with the marks of :func:`literal` taken out (for a text file)."""
    return text.replace(_OPEN, "").replace(_CLOSE, "")


def literal(text: object) -> str:
    """User text inside a form text: drawn as written (an "_" stays an underscore, no unit is
    localised); each word marked alone, so that a line break between words keeps the marks."""
    return " ".join(f"{_OPEN}{w}{_CLOSE}" if w else w for w in str(text).split(" "))


def rich_runs(text: str) -> list[tuple[str, bool]]:
    """``text`` as (run, is a subscript) in order: the book's symbols typeset (``f_пр`` → f with
    the subscript пр), user text (:func:`literal`) as written."""
    return list(_runs(text))


@functools.lru_cache(maxsize=65536)
def _runs(text: str) -> tuple[tuple[str, bool], ...]:
    """:func:`rich_runs` of ``text``, remembered: the forms of a job draw the same labels and
    many of the same numbers, each measured and drawn more than once."""
    out: list[tuple[str, bool]] = []
    pos = 0
    for m in _LITERAL.finditer(text):
        out += _sub_runs(text[pos : m.start()])
        if m.group(1):
            out.append((m.group(1), False))
        pos = m.end()
    out += _sub_runs(text[pos:].replace(_CLOSE, "").replace(_OPEN, ""))
    return tuple(r for r in out if r[0])


def _sub_runs(text: str) -> list[tuple[str, bool]]:
    text = text.replace(_CLOSE, "")
    out: list[tuple[str, bool]] = []
    pos = 0
    for m in _SUBSCRIPT.finditer(text):
        out.append((text[pos : m.start()], False))
        out.append((m.group(1), True))
        pos = m.end()
    out.append((text[pos:], False))
    return out


def localized(pdf: Form, text: str) -> str:
    """``text`` in the form's language (:func:`localized_text`)."""
    return localized_text(text, pdf.lang)


def localized_text(text: str, lang: str) -> str:
    """``text`` in ``lang`` (:func:`stereoplotter.glossary.localize`) outside the user texts it
    holds (:func:`literal`), which keep their marks."""
    if lang == "en" or not text:
        return text
    out, pos = [], 0
    for m in _LITERAL.finditer(text):
        out.append(localize(text[pos : m.start()], lang))
        out.append(m.group(0))
        pos = m.end()
    out.append(localize(text[pos:], lang))
    return "".join(out)


def fits(pdf: Form, height: float) -> bool:
    """True when ``height`` mm still fits on the current page."""
    return pdf.get_y() + height <= pdf.page_break_trigger


def heading(pdf: Form, text: str, size: float = 11.0, keep: float = 0.0) -> None:
    """A bold line; on the next page when it and ``keep`` mm after it do not fit here."""
    lines = wrap_lines(pdf, localized(pdf, text), pdf.epw - 2 * pdf.c_margin, "B", size)
    line = 1.5 * size * _PT + 1.0
    if not fits(pdf, len(lines) * line + keep) and pdf.get_y() > pdf.t_margin + 1.0:
        pdf.add_page()
    pdf.set_font(FONT, "B", size)
    for text_line in lines:  # within the margins, broken at spaces when wider
        pdf.rich_text(pdf.l_margin + pdf.c_margin,
                      pdf.get_y() + 0.5 * line + 0.3 * pdf.font_size, text_line)  # fmt: skip
        pdf.set_xy(pdf.l_margin, pdf.get_y() + line)
    pdf.set_font(FONT, "", 8)


def paragraph(pdf: Form, text: str, size: float = 7.5) -> None:
    """Text over the page width, broken into lines at spaces (:func:`wrap_lines`), left-aligned, on
    the next page when it does not fit the rest of this one (continued over a page only when
    it is longer than a page)."""
    pdf.set_font(FONT, "", size)
    line = 1.3 * size * _PT
    lines = wrap_lines(pdf, localized(pdf, text), pdf.epw - 2 * pdf.c_margin, "", size)
    if not fits(pdf, len(lines) * line) and pdf.get_y() > pdf.t_margin + 1.0:
        pdf.add_page()  # a paragraph is whole on a page (none of the forms' runs over a page)
        pdf.set_font(FONT, "", size)
    for text_line in lines:
        if pdf.get_y() + line > pdf.page_break_trigger:
            pdf.add_page()
            pdf.set_font(FONT, "", size)
        if text_line:
            pdf.rich_text(pdf.l_margin + pdf.c_margin,
                          pdf.get_y() + 0.5 * line + 0.3 * pdf.font_size, text_line)  # fmt: skip
        pdf.set_xy(pdf.l_margin, pdf.get_y() + line)


def table(
    pdf: Form,
    header: Sequence[str],
    rows: Sequence[Sequence[str]],
    widths: Sequence[float],
    size: float = 7.5,
    aligns: Sequence[str] | None = None,
    gap: float = 2.0,
    keep: float = 0.0,
) -> float:
    """A table over the page width, on the next page when it fits a page but not the rest of
    this one; a table longer than a page continues on the next, under the header again (a row
    is never split). ``keep``: mm that must fit on the page before the table (its heading).
    Returns the table's height.

    Laid out here in one pass (each cell's lines broken at spaces by the font's advance widths,
    remembered per string), drawn with the document's low-level text and line calls: the look
    of fpdf2's ``table`` with ``SINGLE_TOP_LINE`` borders (a grey bold header row with a line
    under it), padding 0.5 mm, each cell's lines centred in its row.
    """
    scale = pdf.epw / sum(widths)
    cols = [w * scale for w in widths]
    lefts = [pdf.l_margin + sum(cols[:j]) for j in range(len(cols))]
    aligns = tuple(aligns) if aligns else ("LEFT",) * len(cols)
    line = 1.22 * size * _PT + 0.5
    head = [wrap_lines(pdf, localized(pdf, str(h)), w - 2 * _PAD, "B", size)
            for h, w in zip(header, cols, strict=True)]  # fmt: skip
    body = [[wrap_lines(pdf, localized(pdf, str(c)), w - 2 * _PAD, "", size)
             for c, w in zip(r, cols, strict=True)] for r in rows]  # fmt: skip
    total = sum(_row_height(cells, line) for cells in body)
    total += _row_height(head, line) if any(header) else 0.0
    page = pdf.page_break_trigger - pdf.t_margin
    if not fits(pdf, total) and total + keep <= page:
        pdf.add_page()
    if any(header):  # the header stays with the first row
        first = _row_height(body[0], line) if body else 0.0
        if pdf.get_y() + _row_height(head, line) + first > pdf.page_break_trigger:
            pdf.add_page()
        _draw_row(pdf, head, lefts, cols, aligns, line, size, "B")
    for cells in body:
        if pdf.get_y() + _row_height(cells, line) > pdf.page_break_trigger:
            pdf.add_page()
            if any(header):
                _draw_row(pdf, head, lefts, cols, aligns, line, size, "B")
        _draw_row(pdf, cells, lefts, cols, aligns, line, size, "")
    pdf.set_font(FONT, "", size)
    pdf.set_xy(pdf.l_margin, pdf.get_y() + gap)
    return total


def table_height(
    pdf: Form,
    header: Sequence[str],
    rows: Sequence[Sequence[str]],
    widths: Sequence[float],
    size: float = 7.5,
) -> float:
    """The height (mm) :func:`table` would give these rows."""
    scale = pdf.epw / sum(widths)
    cols = [w * scale for w in widths]
    line = 1.22 * size * _PT + 0.5
    head = [wrap_lines(pdf, localized(pdf, str(h)), w - 2 * _PAD, "B", size)
            for h, w in zip(header, cols, strict=True)]  # fmt: skip
    total = sum(
        _row_height([wrap_lines(pdf, localized(pdf, str(c)), w - 2 * _PAD, "", size)
                     for c, w in zip(r, cols, strict=True)], line)
        for r in rows
    )  # fmt: skip
    return total + (_row_height(head, line) if any(header) else 0.0)


_PAD = 0.5  # mm, the cell padding of the tables
#: The lines of a cell's text by (style, size, width, text): a pure function of the font file.
_LINES: dict[tuple[str, float, float, str], tuple[str, ...]] = {}


def forget_layout() -> None:
    """Forget what the process remembers of the fonts and texts (the parsed fonts, their
    compiled subsets, the text widths, the lines of each cell, the runs of each text), as a
    fresh process starts: the next form is laid out from nothing, to the same bytes."""
    for font in [*_PARSED.values(), *_SUBSETS.values()]:
        font.close()
    for memory in (_PARSED, _SUBSETS, _WIDTHS, _LINES):
        memory.clear()
    _runs.cache_clear()


def _plain_width(pdf: Form, text: str, style: str, size: float) -> float:
    """The advance width of ``text`` in mm at ``size`` pt (remembered, :data:`_WIDTHS`)."""
    _, points = pdf.fonts[f"{FONT.lower()}{style}"].get_text_width(text, size, None)
    return points / pdf.k


def text_width(pdf: Form, text: str, style: str, size: float) -> float:
    """The advance width of a form text as drawn (:func:`rich_runs`), in mm."""
    return sum(_plain_width(pdf, run, style, size * _SUB if sub else size)
               for run, sub in _runs(text))  # fmt: skip


def wrap_lines(pdf: Form, text: str, width: float, style: str, size: float) -> tuple[str, ...]:
    """The lines of ``text`` in a cell ``width`` mm wide: at its newlines, then greedily at
    spaces (a word wider than the cell is broken between characters)."""
    key = (style, size, round(width, 6), text)
    lines = _LINES.get(key)
    if lines is not None:
        return lines
    out: list[str] = []
    for paragraph_ in text.split("\n"):
        current = ""
        for word in paragraph_.split(" "):
            trial = f"{current} {word}" if current else word
            if text_width(pdf, trial, style, size) <= width or not current:
                current = trial
            else:
                out.append(current)
                current = word
            while text_width(pdf, current, style, size) > width and len(current) > 1:
                cut = len(current) - 1
                while cut > 1 and text_width(pdf, current[:cut], style, size) > width:
                    cut -= 1
                out.append(current[:cut])
                current = current[cut:]
        out.append(current)
    if len(_LINES) >= _WIDTHS_MAX:
        _LINES.clear()
    lines = _LINES[key] = tuple(out)
    return lines


def _row_height(cells: Sequence[Sequence[str]], line: float) -> float:
    return max(len(c) for c in cells) * line + 2 * _PAD


def _draw_row(
    pdf: Form,
    cells: Sequence[Sequence[str]],
    lefts: Sequence[float],
    cols: Sequence[float],
    aligns: Sequence[str],
    line: float,
    size: float,
    style: str,
) -> None:
    """One row at the current y: a header row (``style`` "B") filled grey and underlined."""
    top, height = pdf.get_y(), _row_height(cells, line)
    if style == "B":
        pdf.set_fill_color(225)
        pdf.rect(pdf.l_margin, top, sum(cols), height, style="F")
    pdf.set_font(FONT, style, size)
    for lines, x, w, align in zip(cells, lefts, cols, aligns, strict=True):
        y = top + _PAD + (height - 2 * _PAD - len(lines) * line) / 2
        for text in lines:
            if text:
                dx = _PAD
                if align[0] in "RC":
                    free = w - 2 * _PAD - text_width(pdf, text, style, size)
                    dx += free if align[0] == "R" else free / 2
                pdf.rich_text(x + dx, y + 0.5 * line + 0.3 * size / pdf.k, text)
            y += line
    if style == "B":
        pdf.line(pdf.l_margin, top + height, pdf.l_margin + sum(cols), top + height)
    pdf.set_y(top + height)


#: Where a label goes around its point, tried in this order: (dx, dy) of the text's baseline
#: start in font heights, with the label's width subtracted for the left-hand places (w = 1).
_PLACES = (
    (0.6, 1.05, 0), (0.6, -0.35, 0), (-0.6, 1.05, 1), (-0.6, -0.35, 1),
    (-0.5, 1.6, 0.5), (-0.5, -0.9, 0.5), (0.9, 0.35, 0), (-0.9, 0.35, 1),
    (0.6, 2.1, 0), (-0.6, 2.1, 1), (0.6, -1.4, 0), (-0.6, -1.4, 1),
)  # fmt: skip


class LabelPlacer:
    """Writes text labels next to points so that no two labels' boxes overlap.

    A label's box is its advance width (the font's metrics) by the font's ascent and descent
    (0.8 and 0.25 of the size); the first place of :data:`_PLACES` whose box overlaps no
    earlier box is taken, else the one that overlaps least.
    """

    def __init__(
        self, pdf: Form, bounds: tuple[float, float, float, float] | None = None
    ) -> None:
        self.pdf = pdf
        self.boxes: list[tuple[float, float, float, float]] = []
        #: The area labels stay inside (the drawing's frame): a place outside costs more than
        #: any overlap.
        self.bounds = bounds

    def _box(self, x: float, y: float, width: float) -> tuple[float, float, float, float]:
        size = self.pdf.font_size  # mm
        return (x, y - 0.8 * size, x + width, y + 0.25 * size)

    def _overlap(self, box: tuple[float, float, float, float]) -> float:
        total = 0.0
        if self.bounds is not None:
            x0, y0, x1, y1 = self.bounds
            if box[0] < x0 or box[1] < y0 or box[2] > x1 or box[3] > y1:
                total += 1e6
        for b in self.boxes:
            w = min(box[2], b[2]) - max(box[0], b[0])
            h = min(box[3], b[3]) - max(box[1], b[1])
            if w > 0 and h > 0:
                total += w * h
        return total

    def reserve(self, box: tuple[float, float, float, float]) -> None:
        """Keep labels off an area (a symbol, the scale bar)."""
        self.boxes.append(box)

    def _label_width(self, label: str) -> float:
        return text_width(self.pdf, label, self.pdf.font_style, self.pdf.font_size_pt)

    def text(self, x: float, y: float, label: str) -> None:
        """Write at (x, y) as baseline start, and reserve its box (no choice of place)."""
        label = localized(self.pdf, label)
        self.boxes.append(self._box(x, y, self._label_width(label)))
        self.pdf.rich_text(x, y, label)

    def label(self, px: float, py: float, label: str) -> None:
        """Write ``label`` beside the point (px, py) where it overlaps no earlier label."""
        label = localized(self.pdf, label)
        width, size = self._label_width(label), self.pdf.font_size
        best: tuple[float, float, float] | None = None
        for dx, dy, shift in _PLACES:
            x, y = px + dx * size - shift * width, py + dy * size
            cost = self._overlap(self._box(x, y, width))
            if best is None or cost < best[0]:
                best = (cost, x, y)
            if cost == 0.0:
                break
        assert best is not None
        self.text(best[1], best[2], label)
