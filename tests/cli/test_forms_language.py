"""One glossary for every output: sheet.md and the transcript's closing
summary in Russian and English, every key in both languages, a bad language refused."""

from __future__ import annotations

import re

import numpy as np
import pytest

from stereoplotter.glossary import LANGUAGES, TERMS, term
from stereoplotter.io.instrument_file import load_instrument
from stereoplotter.io.scenario_file import load_scenario
from stereoplotter.procedure import simulate
from stereoplotter.report.sheet import sheet_markdown
from stereoplotter.report.simulation import closing_summary, transcript_text
from stereoplotter.setup.sheet import SetupOptions, compute_setup_sheet


def test_every_term_has_both_languages_and_a_bad_language_is_refused():
    for key, texts in TERMS.items():
        assert set(texts) == set(LANGUAGES), key
        assert texts["ru"] and texts["en"], key
        assert not re.search("[А-Яа-яЁё]{3,}", texts["en"].replace("СК-42", "")), key
    with pytest.raises(ValueError, match=r"--lang: expected one of ru, en, found 'de'"):
        term("setup_data", "de")


@pytest.fixture(scope="module")
def sheet():
    scenario = load_scenario("pair60")
    spec = load_instrument("sc1")
    return compute_setup_sheet(scenario, spec, SetupOptions(), np.random.default_rng(scenario.seed))


def test_sheet_markdown_in_russian_uses_the_books_terms(sheet):
    ru, en = sheet_markdown(sheet, "ru"), sheet_markdown(sheet, "en")
    assert en == sheet_markdown(sheet)  # English is the default
    assert ru.startswith("# Установочные данные — pair60, стереограф СЦ-1")
    for expected in ("## Таблица 24", "| фокусное расстояние прибора | f_пр |",
                     "| коэффициенты счётчиков | n_л, n_п |", "## Отсчёты по этапам",
                     "### Этап 2", "левый снимок: k_ω по метке 3", "**(принято)**"):  # fmt: skip
        assert expected in ru, expected
    # the same numbers in both: every number of the English sheet is in the Russian one
    numbers = lambda text: sorted(re.findall(r"-?\d+\.\d+", text))  # noqa: E731
    assert numbers(ru) == numbers(en)


def test_transcript_closing_summary_in_russian():
    run = simulate(load_scenario("pair60"), load_instrument("sc1"), seed=3)
    en, ru = closing_summary(run), closing_summary(run, "ru")
    m = re.search(r"Checks: (\d+) passed, (\d+) failed of (\d+)\.", en)
    assert m is not None
    assert f"Контроли: {m[1]} в допуске, {m[2]} вне допуска из {m[3]}." in ru
    assert ru.startswith("## Итоги") and "Closing summary" not in ru
    assert ru.count("\n- ") == en.count("\n- ")
    text = transcript_text(run, "ru")
    assert text.startswith("## Этап 1") and "[этап 2]" in text and text.endswith(ru)
