"""The Russian and English terms every output shares: the form, ``sheet.md`` and the transcript.

One glossary for the whole program, in the base layer so that every layer that prints may import
it. Russian uses the terms and symbols of Kushtin & Lyskov (1984), ch. 6 (Установочные данные,
n_л, n_п, f_пр, место нуля МО, …); the symbols themselves (M_г, n_л, O_Y3,л …) are the book's in
both languages, as ``docs/nomenclature.md`` maps them. A missing term is an error at import (both
languages are given for every key), never a silent fallback.
"""

from __future__ import annotations

from types import MappingProxyType

__all__ = ["LANGUAGES", "TERMS", "check_language", "term"]

#: The languages of the outputs (``--lang``).
LANGUAGES = ("ru", "en")

# key: (English, Russian). A declarative table, one term a line.
_TABLE: dict[str, tuple[str, str]] = {
    # titles and headers
    "setup_data": ("Setup data", "Установочные данные"),
    "table24": ("Table 24", "Таблица 24"),
    "stereopair": ("stereopair", "стереопара"),
    "page": ("page", "стр."),
    "job": ("job", "работа"),
    "pair": ("pair", "пара"),
    "left_photo": ("left photo", "левый снимок"),
    "right_photo": ("right photo", "правый снимок"),
    "left": ("left", "левый"),
    "right": ("right", "правый"),
    "date": ("date", "дата"),
    "from_job_file": ("from the job file", "из файла работы"),
    "map_sheet": ("map sheet", "лист карты"),
    "instrument": ("instrument", "прибор"),
    "camera": ("camera", "камера"),
    "frame": ("frame", "система координат"),
    "base_direction": (
        "base direction θ from grid east (frame X)",
        "направление базиса θ от оси ȳ сетки (ось X системы)",
    ),
    "assumed": ("assumed", "принято"),
    "assumed_note": (
        "* the value rests on instrument parameters that no source documents "
        "(assumed, docs/instruments.md)",
        "* значение опирается на параметры прибора, не подтверждённые источником "
        "(приняты, docs/instruments.md)",
    ),
    "none": ("none", "нет"),
    "no_map_sheet": ("none (scales forced)", "нет (масштабы заданы)"),
    "fiducials_given_as": ("fiducials given as", "координатные метки заданы как"),
    "frame_local": (
        "the job's local photogrammetric system (no SK-42 tie)",
        "местная фотограмметрическая система работы (без привязки к СК-42)",
    ),
    "frame_sk42": ("§10 local system at SK-42", "местная система §10 в точке СК-42"),
    "item1": ("item 1", "п. 1"),
    # Table 24
    "no": ("No.", "№"),
    "quantity": ("quantity", "величина"),
    "symbol": ("symbol", "обозн."),
    "value": ("value", "значение"),
    "unit": ("unit", "ед."),
    "equation": ("equation", "формула"),
    "notes": ("what for, which stage", "назначение, этап"),
    "scale_horizontal": ("horizontal model scale", "горизонтальный масштаб модели"),
    "scale_vertical": ("vertical model scale", "вертикальный масштаб модели"),
    "transformation_coefficient": ("transformation coefficient", "коэффициент трансформирования"),
    "focal_corrected": ("corrected focal length", "исправленное фокусное расстояние"),
    "f_instrument": ("instrument principal distance", "фокусное расстояние прибора"),
    "base_components": ("base components", "составляющие базиса"),
    "counter_coefficients": ("counter coefficients", "коэффициенты счётчиков"),
    "marks_left": ("marks, left photo", "координаты меток, левый снимок"),
    "marks_right": ("marks, right photo", "координаты меток, правый снимок"),
    "mark_spans": ("mark spans 3–4", "расстояния между метками 3–4"),
    "decentrations": ("decentrations, left; right", "децентрации, левый; правый"),
    "model_heights": (
        "model heights over the height control",
        "высоты модели над опорными точками",
    ),
    "sheet_corners": (
        "sheet corners 1 SW, 2 SE, 3 NE, 4 NW",
        "углы трапеции 1 ЮЗ, 2 ЮВ, 3 СВ, 4 СЗ",
    ),
    "gear_ratio": ("coordinatograph gear", "передача координатографа"),
    "no_gear": ("no map sheet: no coordinatograph gear", "нет листа карты: передача не задаётся"),
    # notes of Table 24
    "note_mg": (
        "set the coordinatograph gear r before stage 1",
        "установить передачу r до этапа 1",
    ),
    "note_mv": (
        "set the height-counter gears before stage 1",
        "установить шестерни счётчика высот",
    ),
    "note_k": (
        "f_пр/f′ = M_г/M_в; tilts the correction planes",
        "f_пр/f′ = M_г/M_в; наклон плоскостей",
    ),
    "note_f1": (
        "from the measured fiducial distances; in (6.1)/(6.2)",
        "по измеренным расстояниям меток; в (6.1)/(6.2)",
    ),
    "note_fpr": ("set on both projectors, stage 1", "устанавливается на обеих камерах, этап 1"),
    "note_b": ("b_x, b_y stage 1; b_z′ stage 2 (6.14)", "b_x, b_y этап 1; b_z′ этап 2 (6.14)"),
    "note_n": (
        "n_л = D_max/f_пр; n_п scales the right photo",
        "n_л = D_max/f_пр; n_п — правый снимок",
    ),
    "note_marks": (
        "targets of k_ω, k_α, stage 2 (6.12)/(6.13)",
        "установка k_ω, k_α, этап 2 (6.12)/(6.13)",
    ),
    "note_L": ("checked in stage 1; (6.9)–(6.11)", "контроль на этапе 1; (6.9)–(6.11)"),
    "note_d": ("decentration scales, stage 2", "шкалы децентраций, этап 2"),
    "note_Z": ("stage 3 readings O_Zi (6.15)", "отсчёты O_Zi этапа 3 (6.15)"),
    "note_corner": ("stage 4; corner 4 checks in stage 5", "этап 4; угол 4 — контроль, этап 5"),
    # stages
    "stage": ("stage", "этап"),
    "stage_1": ("1 · scales, base, spans", "1 · масштабы, базис, метки"),
    "stage_2": ("2 · tilts, decentrations", "2 · наклоны, децентрации"),
    "stage_3": ("3 · height control", "3 · высотные опорные точки"),
    "stage_4": ("4 · sheet corners 1–3", "4 · углы трапеции 1–3"),
    "stage_5": ("5 · corner 4, plan control, check", "5 · угол 4, плановые и контрольные точки"),
    # readings
    "readings_summary": (
        "Readings to set (MO + value at the least count)",
        "Отсчёты для установки (МО + значение с точностью отсчёта)",
    ),
    "readings": ("Readings, stage by stage (6.9)–(6.18)", "Отсчёты по этапам (6.9)–(6.18)"),
    "readings_intro": (
        "Each value is rounded to the least count of its counter or scale (the "
        "value "
        "to set). The right photo's zero readings: MO_X,п = MO_X + b_x, "
        "MO_Y,п = MO_Y + b_y. Write the reading actually set in the last column.",
        "Каждое значение округлено до цены деления счётчика или шкалы (значение "
        "для установки). Места нуля правого снимка: MO_X,п = MO_X + b_x, "
        "MO_Y,п = MO_Y + b_y. В последнюю графу записывается фактический отсчёт.",
    ),
    "step": ("step", "действие"),
    "reading": ("reading to set", "отсчёт для установки"),
    "least_count": ("least count", "цена деления"),
    "tolerance": ("tolerance", "допуск"),
    "set": ("set", "факт."),
    "tolerances": ("tolerances", "допуски"),
    "counters": ("counters", "счётчики"),
    "scales": ("scales", "шкалы"),
    "height_scale": ("height scale", "шкала высот"),
    "abs_height_counter": ("absolute height counter", "абсолютный счётчик высот"),
    # zero readings, corrections
    "zero_readings": (
        "Zero readings MO (found on the instrument, written in)",
        "Места нуля МО (определяются на приборе, вписываются)",
    ),
    "corrections": (
        "Corrections of stage 1 from the measured spans L′ (6.9)–(6.11)",
        "Поправки этапа 1 по измеренным расстояниям L′ (6.9)–(6.11)",
    ),
    "measured": ("measured", "измерено"),
    "factor": ("factor", "множитель"),
    "formula": ("formula", "формула"),
    "result": ("result", "результат"),
    "corr_L_left": ("measured span, left", "измеренное расстояние, левый"),
    "corr_L_right": ("measured span, right", "измеренное расстояние, правый"),
    "corr_dz": ("height correction (6.9)", "поправка высоты (6.9)"),
    "corr_dz_counter": ("new absolute height reading (6.11)", "новый отсчёт счётчика высот (6.11)"),
    "corr_dbz": ("vertical-base correction (6.10)", "поправка b_z (6.10)"),
    "corr_bz": ("new b_z reading (6.11)", "новый отсчёт b_z (6.11)"),
    # stage 5
    "stage5": (
        "Stage 5: final check on the plan control and check points",
        "Этап 5: окончательный контроль по плановым и контрольным точкам",
    ),
    "point": ("point", "точка"),
    "points_stage5": ("plan control and check points", "плановые и контрольные точки"),
    "role": ("role", "назначение"),
    "plan_control": ("plan control", "плановая опорная"),
    "check_point": ("check", "контрольная"),
    "corner": ("corner", "угол"),
    "read": ("read", "отсчёт"),
    # signatures
    "signatures": ("Signatures", "Подписи"),
    "operator": ("operator", "исполнитель"),
    "checker": ("checker", "проверил"),
    "name": ("name", "фамилия"),
    "signature": ("signature", "подпись"),
    # the method's limits
    "limits": (
        "The method's limits: the book's forms against the rigorous (3.17)",
        "Пределы метода: формулы книги против строгих (3.17)",
    ),
    "limit_book": ("book", "книга"),
    "limit_rigorous": ("rigorous", "строго"),
    "limit_difference": ("difference", "разность"),
    "limit_exceeds": ("exceeds the tolerance", "больше допуска"),
    "limit_within": ("within the tolerance", "в допуске"),
    "limit_choice_book": (
        "The values to set are the book's (6.1)/(6.2), (6.5); where they exceed "
        "the tolerance the instrument needs the rigorous values (--rigorous).",
        "Для установки даны значения по (6.1)/(6.2), (6.5) книги; где разность "
        "больше допуска, прибору нужны строгие значения (--rigorous).",
    ),
    "limit_choice_rigorous": (
        "The values to set are the rigorous (3.17) ones (--rigorous); the "
        "book's are printed beside them.",
        "Для установки даны строгие значения (3.17) (--rigorous); значения книги приведены рядом.",
    ),
    "limit_warning": (
        "WARNING: the book's (6.1)/(6.2), (6.5) deviate from the rigorous (3.17) "
        "by more than the stage tolerance; set the rigorous values (table of the "
        "limits).",
        "ВНИМАНИЕ: формулы книги (6.1)/(6.2), (6.5) отличаются от строгих (3.17) "
        "больше допуска этапа; устанавливайте строгие значения (таблица пределов "
        "метода).",
    ),
    # sheet.md (the English entries are the text sheet.md always had)
    "md_title": ("Setup sheet", "Установочные данные"),
    "md_on": ("on", "на приборе"),
    "md_computed": (
        "Computed by stereoplotter after Kushtin & Lyskov (1984), §26, Table 24. "
        "Values "
        "marked **(assumed)** rest on instrument parameters that no source documents "
        "(`docs/instruments.md`).",
        "Вычислено stereoplotter по Куштину и Лыскову (1984), §26, таблица 24. "
        "Значения с пометкой **(принято)** опираются на параметры прибора, не "
        "подтверждённые источником (`docs/instruments.md`).",
    ),
    "md_assumed_flag": ("assumed", "принято"),
    "md_chain": ("Scale chain", "Цепочка масштабов"),
    "md_no_map": ("no map sheet", "нет листа карты"),
    "md_map": ("map", "карта"),
    "md_forced": ("forced; no coordinatograph ratio", "задан; передачи координатографа нет"),
    "md_ratio": ("coordinatograph ratio", "передача координатографа r ="),
    "md_vertical": ("vertical", "вертикальный"),
    "md_depths": (
        "projection distances of the working area",
        "проектирующие расстояния рабочей площади",
    ),
    "md_decentrations": ("decentrations", "децентрации"),
    "md_model_height": ("model height over point", "высота модели над точкой"),
    "md_sheet_corner": ("sheet corner", "угол трапеции"),
    "md_readings": ("Readings, stage by stage", "Отсчёты по этапам"),
    "md_readings_intro": (
        "Every reading is a zero reading (MO, found on the instrument) plus the "
        "signed value. The right photo's zero readings are MO_X,п = MO_X + b_x, "
        "MO_Y,п = MO_Y + b_y.",
        "Каждый отсчёт — место нуля (МО, определяется на приборе) плюс значение "
        "со знаком. Места нуля правого снимка: MO_X,п = MO_X + b_x, "
        "MO_Y,п = MO_Y + b_y.",
    ),
    "md_stage": ("Stage", "Этап"),
    "md_readings_header": (
        "| step | reading | equation | tolerance |",
        "| действие | отсчёт | формула | допуск |",
    ),
    "md_book": ("book", "книга"),
    "md_assumed_params": (
        "Assumed instrument parameters used",
        "Использованные принятые параметры прибора",
    ),
    "md_assumed_params_text": (
        "These values come from no documented source; adjust them in the "
        "instrument YAML if yours differs",
        "Эти значения не подтверждены источником; исправьте их в YAML-файле "
        "прибора, если ваш прибор отличается",
    ),
    "md_table24_header": (
        "| quantity | symbol | value | unit | equation |",
        "| величина | обозн. | значение | ед. | формула |",
    ),
    # the transcript's closing summary (the English entries are the text it always had)
    "cs_title": ("Closing summary", "Итоги"),
    "cs_checks": (
        "Checks: {p} passed, {f} failed of {n}.",
        "Контроли: {p} в допуске, {f} вне допуска из {n}.",
    ),
    "cs_reported": ("reported", "для сведения"),
    "cs_pass": ("pass", "в допуске"),
    "cs_fail": ("FAIL", "ВНЕ ДОПУСКА"),
    "cs_worst": ("worst", "наибольшее"),
    "cs_remedies": ("Remedies applied", "Применённые исправления"),
    "cs_rounds": ("rounds", "повт."),
    "cs_passed_after": ("check passed after", "после них контроль в допуске"),
    "cs_failed_after": ("check still failed after", "после них контроль вне допуска"),
    "cs_nothing": (
        "What went wrong: nothing outside tolerance at the end.",
        "Что пошло не так: в конце всё в допуске.",
    ),
    "cs_wrong": (
        "What went wrong, and what a real operator would do:",
        "Что пошло не так и что сделал бы оператор:",
    ),
    "cs_still_outside": ("still outside tolerance", "по-прежнему вне допуска"),
    "cs_after": ("after", "после"),
    "cs_no_remedy": ("(no remedy in this practice)", "(в этой практике исправлений нет)"),
    "cs_iteration": ("iteration", "итерация"),
    "cs_default_advice": (
        "repeat the step and its check; look for a sheet or reading error before going on",
        "повторить действие и его контроль; прежде чем продолжать, искать ошибку "
        "в установочных данных или в отсчёте",
    ),
    # details and drawing
    "details_marks": (
        "Transformed marks: the book's (6.1)/(6.2) beside the rigorous (3.17), κ = 0",
        "Трансформированные координаты меток: (6.1)/(6.2) книги и строгие (3.17), κ = 0",
    ),
    "photo": ("photo", "снимок"),
    "mark": ("mark", "метка"),
    "drawing": (
        "Sheet frame and control in instrument coordinates (from the left plumb)",
        "Рамка трапеции и опорные точки в координатах прибора (от левой надирной точки)",
    ),
    "scale_bar": ("50 mm of the model", "50 мм модели"),
    "legend": (
        "Triangles: plan/full control; filled circles: height control; open circles: check "
        "points; crosses: the plumbs of the left and right projection centres. X along "
        "the base, Y to the left of it.",
        "Треугольники: плановые (планово-высотные) опорные точки; залитые кружки: "
        "высотные; пустые кружки: контрольные точки; кресты: надирные точки левого и "
        "правого центров проекции. X — по базису, Y — влево от него.",
    ),
}

#: The glossary: key → {"en": …, "ru": …}, read-only.
TERMS = MappingProxyType(
    {key: MappingProxyType({"en": en, "ru": ru}) for key, (en, ru) in _TABLE.items()}
)


def check_language(lang: str) -> str:
    """``lang`` itself when it is one of :data:`LANGUAGES`; else a ValueError of one line (a
    base module imports no sibling, not even ``errors``; the CLI refuses a bad ``--lang`` by
    its choices before any output is rendered)."""
    if lang not in LANGUAGES:
        raise ValueError(f"--lang: expected one of {', '.join(LANGUAGES)}, found {lang!r}")
    return lang


def term(key: str, lang: str) -> str:
    """The term ``key`` in ``lang`` (``"ru"`` or ``"en"``); an unknown key is a KeyError."""
    return TERMS[key][check_language(lang)]
