"""The Russian and English terms every output shares: the form, ``sheet.md`` and the transcript.

One glossary for the whole program, in the base layer so that every layer that prints may import
it. Russian uses the terms and symbols of Kushtin & Lyskov (1984), ch. 6 (Установочные данные,
n_л, n_п, f_пр, место нуля МО, …); the symbols themselves (M_г, n_л, O_Y3,л …) are the book's in
both languages, as ``docs/nomenclature.md`` maps them. A missing term is an error at import (both
languages are given for every key), never a silent fallback.
"""

from __future__ import annotations

import re
from types import MappingProxyType

__all__ = [
    "LANGUAGES",
    "PHRASES",
    "SYMBOLS",
    "TERMS",
    "check_language",
    "instrument_name",
    "localize",
    "parameter_name",
    "term",
    "translate",
]

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
        "(приняты; см. описание приборов)",
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
    "stage_short": ("st.", "эт."),
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
        "value to set). Write the reading actually set in the last column.",
        "Каждое значение округлено до цены деления счётчика или шкалы (значение "
        "для установки). В последнюю графу записывается фактический отсчёт.",
    ),
    "zero_readings_right": (
        "The right photo's zero readings: MO_X,п = MO_X + b_x, MO_Y,п = MO_Y + b_y; each "
        "projector has its own decentration scales and zeros MO_dx, MO_dy.",
        "Места нуля правого снимка: MO_X,п = MO_X + b_x, MO_Y,п = MO_Y + b_y; у каждого "
        "проектора свои шкалы децентраций и свои места нуля MO_dx, MO_dy.",
    ),
    "step": ("step", "действие"),
    "reading": ("reading to set", "отсчёт для установки"),
    "least_count": ("least count", "цена деления"),
    "tolerance": ("tolerance", "допуск"),
    "set": ("set", "факт."),
    "to_set": ("to set", "установить"),
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
        "The values to set are the book's (6.1)/(6.2), (6.5): each is within its stage "
        "tolerance of the rigorous (3.17) (table of the method's limits).",
        "Для установки даны значения книги (6.1)/(6.2), (6.5): каждое отличается от строгого "
        "(3.17) в пределах допуска этапа (таблица пределов метода).",
    ),
    "limit_choice_mixed": (
        "The values to set: a photo's marks and span by the book's (6.1)/(6.2), (6.5) where "
        "all of them are within their stage tolerance, else all by the rigorous (3.17), "
        "marked (3.17), the book's in brackets beside them.",
        "Для установки: метки и расстояние L снимка — по формулам книги (6.1)/(6.2), (6.5), "
        "если все они в пределах допуска этапа, иначе все строгие (3.17), с пометкой (3.17) "
        "и значением книги рядом в скобках.",
    ),
    "limit_choice_rigorous": (
        "The marks and spans to set are the rigorous (3.17) ones for both photos (as asked, "
        "--rigorous); the book's are in brackets beside them.",
        "Метки и расстояния L для установки — строгие (3.17) для обоих снимков (по заказу); "
        "значения книги — рядом в скобках.",
    ),
    "limit_warning": (
        "WARNING: for the {photos} the book's (6.1)/(6.2), (6.5) leave the stage tolerance "
        "(table of the method's limits): the tables give the rigorous (3.17) values to set, "
        "the book's in brackets beside them.",
        "ВНИМАНИЕ: для {photos} значения книги (6.1)/(6.2), (6.5) выходят из допуска этапа "
        "(таблица пределов метода): в таблицах для установки даны строгие значения (3.17), "
        "значения книги — рядом в скобках.",
    ),
    "photo_left": ("left photo", "левого снимка"),
    "photo_right": ("right photo", "правого снимка"),
    "side_left": ("left", "лев."),
    "side_right": ("right", "прав."),
    "residual_q": ("residual q", "остаточный параллакс q"),
    "fiducials_distances": ("distances", "расстояния"),
    "fiducials_coordinates": ("coordinates", "координаты"),
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
    "md_controls": ("controls", "органы управления"),
    "md_settings_of": ("Settings of the", "Установки прибора"),
    "md_settings_depend": (
        "settings depend on φ, ω", "установок зависят от φ, ω",
    ),
    "md_order": ("Order", "Порядок"),
    "md_documented": ("documented", "документировано"),
    "md_assumed_upper": ("ASSUMED", "ПРИНЯТО"),
    "md_settings_header": (
        "| setting | symbol | kind | formula | left | right | unit |",
        "| установка | обозн. | вид | формула | лев. | прав. | ед. |",
    ),
    "md_similarity": ("Similarity (6.8)", "Преобразование подобия (6.8)"),
    "md_control_points": ("control points", "опорных точек"),
    "md_reflection": ("reflection", "отражение"),
    "md_rms_residual": ("RMS residual", "СКО остатков"),
    "md_residuals": ("residuals", "остатки"),
    "md_marks_intro": (
        "Transformed mark coordinates: the book's single-axis (6.1)/(6.2) against the "
        "rigorous (3.17) (κ = 0):",
        "Трансформированные координаты меток: одноосные (6.1)/(6.2) книги против строгих "
        "(3.17) (κ = 0):",
    ),
    "md_marks_header": (
        "| photo | mark | (6.1)/(6.2) mm | (3.17) x⁰, y⁰ mm | difference µm |",
        "| снимок | метка | (6.1)/(6.2) мм | (3.17) x⁰, y⁰ мм | разность, мкм |",
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
    "tr_remedy": ("REMEDY", "ИСПРАВЛЕНИЕ"),
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


# The procedure's record texts (a transcript's steps, equations, remedies and checks), by their
# templates: (English pattern, Russian with the pattern's {groups}), tried in order, the whole
# text matched. A declarative table; the procedure writes English, the transcript is rendered in
# Russian through it (``report/simulation.py``). A text no pattern matches stays English: the
# tests look for such text in the transcripts they render.
_N = r"(?P<{}>[-+]?[\d.]+)"
_ID = r"(?P<{}>[^\s,:;()]+)"
_PHRASE_TABLE: tuple[tuple[str, str], ...] = (
    # stage 1 / C1: the instrument's setting
    ("set the instrument principal distance f_пр", "установить главное расстояние прибора f_пр"),
    ("turn the left cassette: fiducial lines parallel to the axes",
     "повернуть левую кассету: координатные метки параллельно осям"),
    ("turn the right cassette: fiducial lines parallel to the axes",
     "повернуть правую кассету: координатные метки параллельно осям"),
    ("correction mechanisms and decentrations to their zero places",
     "коррекционные механизмы и децентрации — в нулевые положения"),
    ("base carriage: b_x of the sheet", "базисная каретка: b_x по установочным данным"),
    ("base carriage: O_by = MO_by \\+ b_y", "базисная каретка: O_by = MO_by + b_y"),
    (f"b_z′ = {_N.format('v')} \\(found by the levelling, {_ID.format('s')}\\)",
     "b_z′ = {v} (находится горизонтированием, {s})"),
    ("lower the carriage to D = n_л·f_пр", "опустить каретку до D = n_л·f_пр"),
    ("MO_by: right mark on the right cassette centre \\(by turning b_y\\)",
     "MO_by: правая марка на центр правой кассеты (вращением b_y)"),
    ("left mark on the left cassette centre → MO_X", "левая марка на центр левой кассеты → MO_X"),
    ("… and MO_Y", "… и MO_Y"),
    # relative orientation: the six standard points
    (f"standard point {_ID.format('p')}: clear the y-parallax with {_ID.format('c')} "
     f"\\((?P<s>[^)]*)\\) and over-correct by {_N.format('v')} of the turn",
     "стандартная точка {p}: устранить поперечный параллакс элементом {c} ({s}) с "
     "перекоррекцией на {v} поворота"),
    (f"standard point {_ID.format('p')}: clear the y-parallax with {_ID.format('c')} "
     "\\((?P<s>[^)]*)\\)",
     "стандартная точка {p}: устранить поперечный параллакс элементом {c} ({s})"),
    (f"standard point {_ID.format('p')}: fuse, judge the y-parallax",
     "стандартная точка {p}: навести марку, оценить поперечный параллакс"),
    (f"pass {_N.format('k')}: RMS of the six looks {_N.format('v')} µm — first pass: orient again",
     "проход {k}: СКО по шести точкам {v} µm — первый проход: ориентировать ещё раз"),
    (f"pass {_N.format('k')}: RMS of the six looks {_N.format('v')} µm — ratio {_N.format('r')} "
     f"> {_N.format('l')}: no longer decreasing, stop",
     "проход {k}: СКО по шести точкам {v} µm — отношение {r} > {l}: больше не уменьшается, "
     "конец"),
    (f"pass {_N.format('k')}: RMS of the six looks {_N.format('v')} µm — ratio {_N.format('r')} "
     f"≤ {_N.format('l')}: still decreasing",
     "проход {k}: СКО по шести точкам {v} µm — отношение {r} ≤ {l}: ещё уменьшается"),
    # scaling and levelling
    (f"scale: fuse on {_ID.format('a')} and {_ID.format('b')}, model distance against "
     f"{_N.format('d')} mm; turn b_x in proportion",
     "масштаб: навести марку на {a} и {b}, расстояние в модели против {d} mm; изменить b_x "
     "пропорционально"),
    (f"fuse on {_ID.format('p')} \\({_N.format('n')} times, mean\\), slip the height scale to "
     f"H = {_N.format('h')} m",
     "навести марку на {p} ({n}-кратно, среднее), сдвинуть шкалу высот на H = {h} m"),
    (f"fuse on {_ID.format('p')}, slip the height scale to H = {_N.format('h')} m",
     "навести марку на {p}, сдвинуть шкалу высот на H = {h} m"),
    (f"common tilt (?P<a>Δ[αω]) = {_N.format('v')} mrad: turn {_ID.format('c')}",
     "общий наклон {a} = {v} мрад: вращать {c}"),
    (f"level: control point {_ID.format('p')}, height error against point {_ID.format('q')}",
     "горизонтирование: опорная точка {p}, ошибка высоты относительно точки {q}"),
    (f"control point {_ID.format('p')}: fuse, read the height \\({_N.format('n')} times, "
     "mean\\)",
     "опорная точка {p}: навести марку, отсчитать высоту ({n}-кратно, среднее)"),
    (f"control point {_ID.format('p')}: fuse, read the height",
     "опорная точка {p}: навести марку, отсчитать высоту"),
    # the sheet: corners and plan control
    (f"counters to corner {_ID.format('a')}, pin the sheet's corner {_ID.format('b')} under the "
     "needle",
     "счётчики на угол {a}, закрепить угол {b} листа под иглой"),
    (f"counters to corner {_ID.format('a')}, rotate the sheet about corner {_ID.format('b')} "
     f"until the needle meets corner {_ID.format('c')}",
     "счётчики на угол {a}, повернуть лист вокруг угла {b} до совпадения иглы с углом {c}"),
    (f"counters to corner {_ID.format('a')}: misclosure of needle and corner {_ID.format('b')}",
     "счётчики на угол {a}: несовпадение иглы и угла {b}"),
    (f"plan control point {_ID.format('p')}: fuse, needle against the plotted point",
     "плановая опорная точка {p}: навести марку, игла против нанесённой точки"),
    (f"scale: fuse on the {_N.format('n')} plan control points, counters' spread against the "
     f"plotted points' {_N.format('d')} mm; turn b_x in proportion",
     "масштаб: навести марку на {n} плановых опорных точек, разброс по счётчикам против {d} mm "
     "нанесённых точек; изменить b_x пропорционально"),
    ("lay the sheet on the needle positions of the plan control points \\(least squares: "
     "centroid on centroid, turned onto them\\)",
     "уложить лист на положения иглы на плановых опорных точках (МНК: центр на центр, "
     "с поворотом)"),
    # the setup-data method (§26): stages 1–3 from the sheet
    ("base carriage: O_bx = MO_bx \\+ b_x", "базисная каретка: O_bx = MO_bx + b_x"),
    ("lower the carriage to O_Z = n_л·f_пр \\(absolute height counter\\)",
     "опустить каретку до O_Z = n_л·f_пр (счётчик абсолютных высот)"),
    (f"measure L′_(?P<s>[лп]) \\(marks 3, 4\\), compare with L_(?P<t>[лп]) = {_N.format('v')} mm",
     "измерить L′_{s} (метки 3, 4), сравнить с L_{t} = {v} mm"),
    ("n = D/f_пр at the carriage's bottom stop \\(D_max\\): f′_пр = f_пр·D/\\(D \\+ ΔD\\), "
     "shortened for a deeper carriage, lengthened back \\(to the sheet's f_пр at most\\) for a "
     "shallower one",
     "n = D/f_пр у нижнего упора каретки (D_max): f′_пр = f_пр·D/(D + ΔD), уменьшить для более "
     "глубокой каретки, вернуть обратно (не более f_пр листа) для менее глубокой"),
    ("MO_bx: the left mark on the left cassette centre, the right mark on the right one "
     "\\(two monocular pointings along x\\)",
     "MO_bx: левая марка на центр левой кассеты, правая — на центр правой (два монокулярных "
     "наведения по x)"),
    ("κ_(?P<s>[лп]) from the fiducials: marks 3 and 4 at equal x-readings",
     "κ_{s} по координатным меткам: равные отсчёты x на метках 3 и 4"),
    ("(?P<p>left|right) photo: k_ω to the mean of its fits at marks 3 and 4 \\(least squares\\)",
     "{p} снимок: k_ω на среднее установок по меткам 3 и 4 (метод наименьших квадратов)"),
    ("Δb_z \\(6.10\\), ratio form with D_п = D \\+ b_z and L′_п \\(decision D9\\): "
     "O′_bz = O_bz \\+ Δb_z",
     "Δb_z (6.10) в форме отношения с D_п = D + b_z и L′_п (решение D9): O′_bz = O_bz + Δb_z"),
    (f"ΔZ = {_N.format('v')} m \\(6.9\\): lower the carriage, O′_Z = O_Z \\+ ΔZ",
     "ΔZ = {v} m (6.9): опустить каретку, O′_Z = O_Z + ΔZ"),
    ("record MO_Z on the height scale", "записать MO_Z по шкале высот"),
    ("record MO_bz = \\(b_z reading\\) − b_z′", "записать MO_bz = (отсчёт b_z) − b_z′"),
    ("right mark on the right cassette centre → MO_X,п",
     "правая марка на центр правой кассеты → MO_X,п"),
    ("… and MO_Y,п", "… и MO_Y,п"),
    (f"(?P<p>left|right) photo: counter (?P<a>[XY]) at (?P<f>[^=]+) = {_N.format('v')} mm, turn "
     f"(?P<d>.+) \\({_ID.format('c')}\\) \\((?P<u>tan [αω])\\) until mark (?P<m>\\d) is "
     "under the measuring mark",
     "{p} снимок: счётчик {a} на {f} = {v} mm, вращать {d} ({c}) ({u}) до совмещения метки {m} "
     "с измерительной маркой"),
    ("(?P<p>left|right) photo: check mark 4 at (?P<f>.+)", "{p} снимок: проверить метку 4 при {f}"),
    (f"decentration (?P<d>.+) \\({_ID.format('c')}\\) = (?P<f>[^(]+) \\(place of zero "
     f"(?P<z>MO_d[xy]) = {_N.format('v')} mm\\)",
     "децентрация {d} ({c}) = {f} (место нуля {z} = {v} mm)"),
    (f"standard point {_ID.format('p')}: clear the y-parallax with (?P<c>κ_[лп])",
     "стандартная точка {p}: устранить поперечный параллакс вращением {c}"),
    (f"residual y-parallax at standard point {_ID.format('p')}",
     "остаточный поперечный параллакс в стандартной точке {p}"),
    (f"turn {_ID.format('c')} by the least-squares clearing of the six q seen",
     "вращать {c} по уравниванию шести наблюдённых q (метод наименьших квадратов)"),
    (f"height scale to O_Z{_ID.format('n')} for control point {_ID.format('p')}",
     "шкалу высот на O_Z{n} для опорной точки {p}"),
    (f"fuse the mark on point {_ID.format('p')} by turning b_x",
     "совместить марку с точкой {p} вращением b_x"),
    (f"slip the height scale to H = {_N.format('h')} m", "сдвинуть шкалу высот на H = {h} m"),
    (f"control point {_ID.format('p')}: fuse, read the height, against the point's known height "
     f"{_N.format('h')} m",
     "опорная точка {p}: навести марку, отсчитать высоту, сравнить с известной высотой {h} m"),
    (f"control point {_ID.format('p')}: fuse, read the height \\({_N.format('n')} times, mean\\), "
     f"against the point's known height {_N.format('h')} m",
     "опорная точка {p}: навести марку, отсчитать высоту ({n}-кратно, среднее), сравнить с "
     "известной высотой {h} m"),
    (f"scale: fuse on {_ID.format('a')} and {_ID.format('b')}, counter distance against the "
     f"sheet's {_N.format('d')} mm \\(6.7\\); turn b_x in proportion",
     "масштаб: навести марку на {a} и {b}, расстояние по счётчикам против {d} mm по листу (6.7); "
     "изменить b_x пропорционально"),
    (f"fuse on {_ID.format('p')} \\({_N.format('n')} times\\), slip the height scale to "
     f"H = {_N.format('h')} m",
     "навести марку на {p} ({n}-кратно), сдвинуть шкалу высот на H = {h} m"),
    (f"level: common tilt (?P<a>Δφ_[ao]) = {_N.format('v')} mrad, turn {_ID.format('c')}",
     "горизонтирование: общий наклон {a} = {v} мрад, вращать {c}"),
    # the correction mechanisms' names (gimbal, lens shift, plates), inside the steps above
    ("photo-carrier tilt (?P<a>[αω]) \\(gimbal\\)",
     "наклон снимкодержателя {a} (карданный подвес)"),
    ("photo-carrier decentration (?P<a>[xy])", "децентрация снимкодержателя {a}"),
    ("lens-shift mechanism (?P<a>δ_[αω])", "механизм смещения объектива {a}"),
    ("photo-carriage decentration (?P<a>[xy])", "децентрация снимкодержателя {a}"),
    ("correction plane (?P<a>k[αω]) \\(follower\\)", "коррекционная плоскость {a} (копир)"),
    ("photo decentration (?P<a>[xy]) \\(from the plane settings\\)",
     "децентрация снимка {a} (по установке плоскостей)"),
    ("left", "левый"),
    ("right", "правый"),
    # the equation or decision behind a record
    ("item 1", "п. 1"),
    (f"stage {_ID.format('s')}", "этап {s}"),
    (f"decision {_ID.format('d')}", "решение {d}"),
    ("scale by b_x", "масштаб по b_x"),
    ("conventional method: the model to the scale of the plotted control",
     "обычный способ: модель в масштаб нанесённых опорных точек"),
    ("conventional method: the sheet on the plotted control",
     "обычный способ: лист по нанесённым опорным точкам"),
    ("assumption", "допущение"),
    ("levelling \\(assumption\\)", "горизонтирование (допущение)"),
    ("stopping rule", "правило остановки"),
    ("≤ ¼ mark", "≤ ¼ марки"),
    ("\\(6.5\\), decision D5", "(6.5), решение D5"),
    ("f′·tan (?P<a>[αω]) \\(§2.4\\)", "f′·tan {a} (§2.4)"),
    ("f′·tan (?P<a>[αω]) \\(kinematics §2.4\\)", "f′·tan {a} (описание кинематики, §2.4)"),
    ("§26 stages 2, 3: κ along the initial direction; refine k_ω",
     "§26, этапы 2, 3: κ по начальному направлению; уточнить k_ω"),
    ("§26 stage 3: scaling refined \\(b_x\\)", "§26, этап 3: уточнение масштаба (b_x)"),
    ("levelling on control \\(assumption, q-neutral common tilt\\)",
     "горизонтирование по опорным точкам (допущение: общий наклон, не меняющий q)"),
    # remedies and checks (the closing summary)
    ("(?P<r>C?R\\d+) (?P<b>.+)", "{r} {b}"),
    ("read the control heights as the mean of several fusings",
     "отсчитывать высоты опорных точек как среднее нескольких наведений"),
    ("refine the relative orientation only where q fails, then check the heights again",
     "уточнить взаимное ориентирование только там, где q вне допуска, затем снова проверить "
     "высоты"),
    ("refine the relative orientation", "уточнить взаимное ориентирование"),
    ("refine scaling and levelling on control",
     "уточнить масштаб и горизонтирование по опорным точкам"),
    ("\\|L − L′\\|", "|L − L′|"),
    (f"mark {_ID.format('m')}", "метка {m}"),
    (f"residual y-parallax \\({_N.format('n')} points\\)",
     "остаточный поперечный параллакс ({n} точек)"),
    ("levelling points \\(against the first\\)", "точки горизонтирования (относительно первой)"),
    ("control heights", "высоты опорных точек"),
    (f"corner {_ID.format('c')}", "угол {c}"),
    ("plan control points \\(needle − plotted\\)", "плановые опорные точки (игла − нанесённая)"),
    # the instruments' settings and controls (sheet.md: the settings of the instrument)
    ("2 tilts on the k_α, k_ω scales and 2 decentrations per photo",
     "2 наклона по шкалам k_α, k_ω и 2 децентрации на снимок"),
    ("not documented for the SC-1; the book's §26 names the k_α, k_ω scales of the correction "
     "mechanisms and the decentration scales of each photo",
     "для СЦ-1 не документировано; в §26 книги названы шкалы k_α, k_ω коррекционных механизмов "
     "и шкалы децентраций каждого снимка"),
    ("tilt each photo carrier on its k_α, k_ω scales \\(stage 2 fits them on the fiducial "
     "marks\\)",
     "наклонить каждый снимкодержатель по шкалам k_α, k_ω (на этапе 2 они подбираются по "
     "координатным меткам)"),
    ("set the decentrations d_x, d_y on their scales \\(stage 2, after the fit\\)",
     "установить децентрации d_x, d_y по их шкалам (этап 2, после подбора)"),
    ("photo-carrier tilt (?P<a>[αω]) \\(gimbal, (?P<k>k_[αω]) scale\\)",
     "наклон снимкодержателя {a} (карданный подвес, шкала {k})"),
    ("the 3 kinds of decentration \\(photo, correction mechanism, follower\\) × x, y × 2 "
     "photos, set after kα, kω are introduced",
     "3 вида децентраций (снимка, коррекционного механизма, копира) × x, y × 2 снимка, "
     "устанавливаемых после введения kα, kω"),
    ("documented for the SPR-2 \\(12 settings depending on φ, ω: photo decentrations, "
     "decentrations of the correction mechanisms and of the followers\\); taken for the SPR-3",
     "документировано для СПР-2 (12 установок, зависящих от φ, ω: децентрации снимков, "
     "коррекционных механизмов и копиров); принято для СПР-3"),
    ("introduce dφ, dω: set kα, kω on the lens-shift mechanisms of each photo \\(stage 2 fits "
     "them on the fiducial marks\\)",
     "ввести dφ, dω: установить kα, kω на механизмах смещения объектива каждого снимка (на "
     "этапе 2 они подбираются по координатным меткам)"),
    ("from the tables \\(arguments dφ, dω\\) set the photo-carriage decentrations e, the "
     "correction-mechanism decentrations c and the followers' decentrations u, all f′·tan α, "
     "f′·tan ω",
     "по таблицам (аргументы dφ, dω) установить децентрации кареток снимков e, коррекционных "
     "механизмов c и копиров u, все f′·tan α, f′·tan ω"),
    ("repeat the cycle until the check passes \\(the photo moves under the fixed marks\\)",
     "повторять цикл до выполнения контроля (снимок перемещается под неподвижными марками)"),
    ("lens-shift mechanism (?P<a>k[αω])", "механизм смещения объектива {a}"),
    ("correction-mechanism decentration (?P<a>[xy])", "децентрация коррекционного механизма {a}"),
    ("follower decentration (?P<a>[xy]) \\(correction plate\\)",
     "децентрация копира {a} (коррекционная пластина)"),
    ("2 plate inclinations \\(primary\\) and 2 photo decentrations \\(derived\\) per photo",
     "2 наклона пластин (основные) и 2 децентрации снимка (производные) на снимок"),
    ("SD stereograph: 8 setting elements, the plate inclinations primary, the photo "
     "decentrations mediated \\(report on the Soviet affine plotters, ISP Comm. II\\)",
     "стереограф СД: 8 установочных элементов, наклоны пластин — основные, децентрации "
     "снимков — опосредованные (доклад о советских аффинных приборах, МОФ, комиссия II)"),
    ("incline the correction plates of each photo to θ_α, θ_ω \\(stage 2 fits them on the "
     "fiducial marks: the k_α, k_ω knobs\\)",
     "наклонить коррекционные пластины каждого снимка на θ_α, θ_ω (на этапе 2 они "
     "подбираются по координатным меткам: рукоятки k_α, k_ω)"),
    ("the photo decentrations follow from the plate settings, d = \\(f′/k\\)·tan θ \\(on the "
     "virtual SD-3 the linkage carries them, decision D1\\); check their scales",
     "децентрации снимков следуют из установки пластин, d = (f′/k)·tan θ (на виртуальном "
     "СД-3 их передаёт связь, решение D1); проверить их шкалы"),
    ("correction-plate inclination \\((?P<a>[αω])\\)", "наклон коррекционной пластины ({a})"),
    ("photo decentration (?P<a>[xy]) \\(from the plate\\)", "децентрация снимка {a} (от пластины)"),
    ("primary", "основная"),
    ("derived", "производная"),
    ("mark (?P<m>\\w+) is under the measuring mark", "метка {m} под измерительной маркой"),
    ("the photo carriage brings mark (?P<m>\\w+) under the fixed measuring mark",
     "каретка снимка подводит метку {m} под неподвижную измерительную марку"),
)  # fmt: skip

#: The record texts' templates, compiled: (pattern, Russian).
PHRASES: tuple[tuple[re.Pattern[str], str], ...] = tuple(
    (re.compile(pattern), russian) for pattern, russian in _PHRASE_TABLE
)


def translate(text: str, lang: str) -> str:
    """A record text of the procedure (a step, an equation, a remedy, a check) in ``lang``: the
    first template of :data:`PHRASES` matching the whole text, filled with its values (each
    value translated in turn: a mechanism's name, "left"); a
    ``"stage N: …"`` prefix is translated in front of the rest. English, or a text no template
    matches, is returned as it is.

    >>> translate("standard point 3: fuse, judge the y-parallax", "ru")
    'стандартная точка 3: навести марку, оценить поперечный параллакс'
    >>> translate("stage 5: corner 4", "ru")
    'этап 5: угол 4'
    """
    if check_language(lang) == "en" or not text:
        return text
    for pattern, russian in PHRASES:
        m = pattern.fullmatch(text)
        if m:
            return russian.format(**{k: translate(v, lang) for k, v in m.groupdict().items()})
    head, sep, rest = text.partition(": ")
    if sep and rest:
        first, second = translate(head, lang), translate(rest, lang)
        if (first, second) != (head, rest):
            return f"{first}: {second}"
    return text


#: The instruments by their shipped key, as the Russian forms name them (the English forms print
#: the instrument file's own ``name``).
_INSTRUMENTS_RU = {
    "sc1": "стереограф СЦ-1",
    "spr3": "стереопроектор СПР-3 Г. В. Романовского",
    "sd3": "стереограф СД-3 Ф. В. Дробышева",
}


def instrument_name(key: str, title: str, lang: str) -> str:
    """The instrument's name in ``lang``: the file's ``title`` in English; in Russian the book's
    name of a shipped instrument, else the Cyrillic part of the title (a user's instrument file
    names itself)."""
    if check_language(lang) == "en":
        return title
    if key in _INSTRUMENTS_RU:
        return _INSTRUMENTS_RU[key]
    head = title.split(" (")[0].split(",")[0]
    return head if re.search("[А-Яа-яЁё]", head) else "прибор"


#: The instrument file's parameters an outputs may list as assumed, in Russian.
_PARAMETERS_RU = {
    "gears.coordinatograph_ratios": "передачи координатографа",
    "gears.vertical_scale_denominators": "знаменатели вертикального масштаба",
    "gears.max_photo_to_map_enlargement": "наибольшее увеличение снимка до карты",
    "mark.diameter_mm": "диаметр марки",
    "model.x_offset_mm": "смещение модели по X",
    "model.y_offset_mm": "смещение модели по Y",
    "projection.distance_mm": "проектирующие расстояния",
    "projection.distance_max_mm": "наибольшее проектирующее расстояние",
    "projection.f_instrument_mm": "диапазон f_пр",
    "base.x_mm": "диапазон b_x",
    "base.y_mm": "диапазон b_y",
    "base.z_mm": "диапазон b_z",
    "orientation.kappa_deg": "диапазон κ",
    "correction.tilt_max_deg": "наибольший наклон",
    "correction.decentration_mm": "диапазон децентраций",
    "counters.xy_least_count_mm": "цена деления счётчиков X, Y",
    "counters.z_abs_least_count_mm": "цена деления счётчика высот",
    "counters.height_scale_least_count_m": "цена деления шкалы высот",
    "counters.scale_least_count_mm": "цена деления шкал",
    "tolerances.corner4_mm": "допуск угла 4",
    "tolerances.L_check_times_n_mm": "допуск |L − L′|",
    "tolerances.mark_fit_per_n_mm": "допуск метки 4",
    "tolerances.residual_q_fraction_of_mark": "допуск остаточного параллакса",
    "tolerances.control_height_denominator": "допуск высот опорных точек",
}


def parameter_name(key: str, lang: str) -> str:
    """An instrument file's dotted key in ``lang``: the key itself in English, its Russian name
    (or "параметр прибора" for a key outside :data:`_PARAMETERS_RU`) in Russian."""
    if check_language(lang) == "en":
        return key
    return _PARAMETERS_RU.get(key, "параметр прибора")


#: The units, compass corners and abbreviations of a finished text, English → Russian
#: (:func:`localize`): each a whole token (no letter on either side).
_LOCAL_RU = (
    (r"µm", "мкм"), (r"mrad", "мрад"), (r"mm", "мм"), (r"m", "м"), (r"tan", "tg"),
    (r"SW", "ЮЗ"), (r"SE", "ЮВ"), (r"NE", "СВ"), (r"NW", "СЗ"), (r"RMS", "СКО"),
    (r"MO", "МО"), (r"Gauss–Krüger", "Гаусса–Крюгера"), (r"map", "карты"),
)  # fmt: skip
_LOCAL_RU_PATTERN = re.compile(  # a unit is no part of an identifier (``distance_mm``)
    r"(?<![A-Za-zА-Яа-яЁё_.])(" + "|".join(a for a, _ in _LOCAL_RU if a not in ("map", "MO"))
    + r")(?![A-Za-zА-Яа-яЁё_])|(?<=_)(map)(?![A-Za-zА-Яа-яЁё_])"
    r"|(?<![A-Za-zА-Яа-яЁё_.])(MO)(?![A-Za-zА-Яа-яЁё])"
)
_LOCAL_RU_MAP = dict(_LOCAL_RU)


def localize(text: str, lang: str) -> str:
    """A finished text of an output with its units (mm → мм, m → м, µm → мкм), compass
    corners (SW → ЮЗ …), the zero reading МО, tan → tg and RMS → СКО in ``lang``: the
    symbols a Russian reader writes in Cyrillic, each replaced only as a whole token (a
    letter on neither side, so ``m/mm`` → ``м/мм``, never inside a word or an identifier such
    as ``distance_mm``); the subscript of ``M_map`` → ``M_карты``. English is returned as it
    is.

    >>> localize("L = 287.70 mm, ΔZ 5.14 m/mm, corner 4 NW, MO_X", "ru")
    'L = 287.70 мм, ΔZ 5.14 м/мм, corner 4 СЗ, МО_X'
    """
    if check_language(lang) == "en" or not text:
        return text
    return _LOCAL_RU_PATTERN.sub(lambda m: _LOCAL_RU_MAP[m.group(m.lastindex or 1)], text)


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


# --- the symbols a trainee meets on the page: what each means, in plain words -------------------

#: Symbol (as the page and the operator's steps write it) → (English, Russian) explanation. The
#: page finds these in every text it shows and puts the explanation one hover or tap away.
#: Longer symbols first where one contains another (``MO_bx`` before ``MO``).
_SYMBOL_TABLE: dict[str, tuple[str, str]] = {
    "MO": (
        "place of zero (место нуля): what a counter reads when its element stands at its zero "
        "position (e.g. the mark exactly on the cassette centre). A setting from the sheet is "
        "then made as MO + value; MO_X, MO_Y, MO_bx, MO_by, MO_bz, MO_Z, MO_dx are those of X, "
        "Y, b_x, b_y, b_z, Z and the decentrations.",
        "место нуля (МО): отсчёт счётчика при нулевом положении элемента (например, марка точно "
        "на центре кассеты). Установка по листу делается как МО + величина; MO_X, MO_Y, MO_bx, "
        "MO_by, MO_bz, MO_Z, MO_dx — места нуля X, Y, b_x, b_y, b_z, Z и децентраций.",
    ),
    "O_": (
        "O (отсчёт): the reading to set on a counter, e.g. O_bx = MO_bx + b_x; O′ is the "
        "reading after a correction, O′ = O + Δ (6.11).",
        "O (отсчёт): отсчёт, устанавливаемый на счётчике, например O_bx = MO_bx + b_x; O′ — "
        "отсчёт после поправки, O′ = O + Δ (6.11).",
    ),
    "M_в": (
        "vertical scale of the model 1:M_в (the heights' scale). The height counter is geared "
        "for it (the 'gear' action) so that the metre height scale H reads ground heights.",
        "вертикальный масштаб модели 1:M_в (масштаб высот). На него настраивается счётчик "
        "высот (действие 'gear'), чтобы шкала высот H показывала высоты местности в метрах.",
    ),
    "M_г": (
        "horizontal scale of the model 1:M_г (the plan scale of the model in the instrument).",
        "горизонтальный масштаб модели 1:M_г (масштаб модели в плане).",
    ),
    "n_л": (
        "scale coefficient of the left photo: how many times the model is larger than the "
        "photo, n_л = D/f_пр (projection distance over the instrument principal distance). "
        "n_п is the right photo's.",
        "коэффициент масштаба левого снимка: во сколько раз модель крупнее снимка, "
        "n_л = D/f_пр (проектирующее расстояние на фокусное расстояние прибора). n_п — правого.",
    ),
    "n_п": (
        "scale coefficient of the right photo, n_п = D_п/f_пр (see n_л).",
        "коэффициент масштаба правого снимка, n_п = D_п/f_пр (см. n_л).",
    ),
    "f_пр": (
        "instrument principal distance (фокусное расстояние прибора): the distance set in the "
        "instrument between the projection centre and the photo, f_пр = k·f′. Control "
        "'f_пр'; sheet row 'f_пр' of the interior part.",
        "фокусное расстояние прибора: расстояние между центром проекции и снимком, "
        "устанавливаемое в приборе, f_пр = k·f′. Орган 'f_пр'; строка 'f_пр' листа.",
    ),
    "f′": (
        "the camera's focal length corrected for film deformation (the certificate's f).",
        "фокусное расстояние камеры, исправленное за деформацию плёнки (f паспорта).",
    ),
    "D": (
        "projection distance: from the projection centre to the model, read on the Z counter; "
        "D = n·f_пр.",
        "проектирующее расстояние: от центра проекции до модели, отсчитывается по счётчику Z; "
        "D = n·f_пр.",
    ),
    "L-check": (
        "the check of the scale coefficient n in stage 1: put the mark on fiducial marks 3 and 4 "
        "of a photo, read Y at each; their difference L′ must equal L (the sheet's span, (6.5)) "
        "within 0.03/n_л mm. If not, raise or lower the carriage by ΔZ (6.9) and correct b_z "
        "by Δb_z (6.10).",
        "L-контроль коэффициента масштаба n на этапе 1: навести марку на координатные метки 3 и "
        "4 снимка, отсчитать Y; разность L′ должна равняться L (по листу, (6.5)) с допуском "
        "0.03/n_л мм. Иначе поднять или опустить каретку на ΔZ (6.9) и исправить b_z на Δb_z "
        "(6.10).",
    ),
    "L′": (
        "the span between fiducial marks 3 and 4 as measured on the Y counter (L′_л left, "
        "L′_п right).",
        "расстояние между метками 3 и 4, измеренное по счётчику Y (L′_л левый, L′_п правый).",
    ),
    "L_л": (
        "the span between fiducial marks 3 and 4 the model should show on the Y counter (left "
        "photo); L_п the right photo's. The sheet gives (6.5) with the transformed marks; the "
        "step with the correction units at zero compares with n·(y₃ − y₄) of the measured marks "
        "(decision D5), which differs by a few hundredths of a mm.",
        "расстояние между метками 3 и 4, которое должна показать модель по счётчику Y (левый "
        "снимок); L_п — правый. Лист даёт (6.5) по трансформированным меткам; шаг с "
        "коррекционными устройствами в нуле сравнивает с n·(y₃ − y₄) измеренных меток "
        "(решение D5); разница — сотые доли мм.",
    ),
    "ΔZ": (
        "correction of the projection distance (6.9): the carriage is raised or lowered by ΔZ "
        "when the L-check fails.",
        "поправка проектирующего расстояния (6.9): каретку поднимают или опускают на ΔZ, если "
        "L-контроль не выполнен.",
    ),
    "Δb_z": (
        "correction of the base component b_z (6.10) when the right photo's L-check fails.",
        "поправка составляющей базиса b_z (6.10), если L-контроль правого снимка не выполнен.",
    ),
    "b_x": (
        "base component along X: the distance between the two projection centres in the "
        "instrument, b_x = B/M_г. Control 'b_x'.",
        "составляющая базиса по X: расстояние между центрами проекции в приборе, b_x = B/M_г. "
        "Орган 'b_x'.",
    ),
    "b_y": ("base component along Y (control 'b_y').", "составляющая базиса по Y (орган 'b_y')."),
    "b_z": ("base component along Z (control 'b_z').", "составляющая базиса по Z (орган 'b_z')."),
    "κ": (
        "kappa: the turn of a cassette (photo) in its own plane (controls 'κ left', 'κ right').",
        "каппа: поворот кассеты (снимка) в своей плоскости (органы 'κ left', 'κ right').",
    ),
    "k_α": (
        "correction knob α: tilts the photo carrier along the base (its scale in tan α; "
        "controls 'k_α left', 'k_α right').",
        "коррекционный винт α: наклон снимкодержателя вдоль базиса (шкала в tan α; органы "
        "'k_α left', 'k_α right').",
    ),
    "k_ω": (
        "correction knob ω: tilts the photo carrier across the base (its scale in tan ω; "
        "controls 'k_ω left', 'k_ω right').",
        "коррекционный винт ω: наклон снимкодержателя поперёк базиса (шкала в tan ω; органы "
        "'k_ω left', 'k_ω right').",
    ),
    "decentration": (
        "decentration: the shift of the photo carrier in its plane (controls 'dx left', "
        "'dy left', …) that goes with a tilt, d = f′·tan α; its counters read 20.00 mm at their "
        "place of zero MO_dx, MO_dy.",
        "децентрация: сдвиг снимкодержателя в своей плоскости (органы 'dx left', 'dy left', …), "
        "сопровождающий наклон, d = f′·tan α; в месте нуля MO_dx, MO_dy счётчики показывают "
        "20.00 мм.",
    ),
    "y-parallax": (
        "y-parallax q: the vertical offset between what the left and the right eye see at a "
        "point; the model is relatively oriented when q ≈ 0 at the six standard points.",
        "поперечный параллакс q: вертикальное расхождение изображений для левого и правого глаза "
        "в точке; модель взаимно ориентирована, когда q ≈ 0 в шести стандартных точках.",
    ),
    "x-parallax": (
        "x-parallax p: the offset along the base; the mark sits on the ground when p = 0 "
        "(turn Z, the foot wheel, to fuse the mark).",
        "продольный параллакс p: расхождение вдоль базиса; марка на поверхности при p = 0 "
        "(вращать Z, ножной штурвал, до слияния марки).",
    ),
    "standard point": (
        "standard points 1–6: the six places of the overlap where the y-parallax is cleared "
        "(1, 2 near the principal points, 3–6 above and below them).",
        "стандартные точки 1–6: шесть мест зоны перекрытия, где устраняют поперечный параллакс "
        "(1, 2 у главных точек, 3–6 над и под ними).",
    ),
    "least count": (
        "least count: the smallest step a counter shows (0.01 mm on X, Y): a tolerance below "
        "it cannot be seen on the counter, only in the eyepieces.",
        "цена деления: наименьший шаг, который показывает счётчик (0.01 мм по X, Y): допуск "
        "меньше неё виден не на счётчике, а только в окулярах.",
    ),
    "decision": (
        "decision D1…D10: a choice this program made where the book is silent or ambiguous "
        "(listed in docs/procedure.md and docs/instruments.md).",
        "решение D1…D10: выбор программы там, где книга молчит или неоднозначна (перечислены в "
        "docs/procedure.md и docs/instruments.md).",
    ),
    "(6.": (
        "an equation number of Kushtin & Lyskov (1984), chapter 6: (6.5) the span L of marks "
        "3–4, (6.7) the model scale by b_x, (6.9) ΔZ, (6.10) Δb_z, (6.11) O′ = O + Δ, "
        "(6.12)/(6.13) the mark coordinates.",
        "номер формулы Куштин, Лысков (1984), гл. 6: (6.5) расстояние L меток 3–4, (6.7) "
        "масштаб модели по b_x, (6.9) ΔZ, (6.10) Δb_z, (6.11) O′ = O + Δ, (6.12)/(6.13) "
        "координаты меток.",
    ),
    "C1": (
        "conventional method, stage C1: interior orientation (f_пр, photos on their fiducials, "
        "correction elements at zero).",
        "обычный способ, этап C1: внутреннее ориентирование.",
    ),
    "C2": (
        "conventional method, stage C2: relative orientation, clearing the y-parallax at the "
        "six standard points element by element.",
        "обычный способ, этап C2: взаимное ориентирование по шести стандартным точкам.",
    ),
    "C3": (
        "conventional method, stage C3: absolute orientation (scale by b_x, levelling on the "
        "control heights).",
        "обычный способ, этап C3: внешнее ориентирование (масштаб по b_x, горизонтирование).",
    ),
    "C4": (
        "conventional method, stage C4: the coordinatograph and the map sheet.",
        "обычный способ, этап C4: координатограф и лист карты.",
    ),
}

#: The symbols and their explanations (read only): symbol → {"en": …, "ru": …}.
SYMBOLS = MappingProxyType(
    {k: MappingProxyType({"en": en, "ru": ru}) for k, (en, ru) in _SYMBOL_TABLE.items()}
)
