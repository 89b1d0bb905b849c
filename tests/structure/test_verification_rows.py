"""A verification row is declared once, in its topic module, and the table finds it: every
``verification/rows_*.py`` module's declared rows are among the table's ``ROW_MODULES``, and the
table holds each row once."""

from __future__ import annotations

import importlib
from pathlib import Path

import stereoplotter.verification as verification
from stereoplotter.verification import table
from stereoplotter.verification.entry import BOOK

TOPICS = sorted(p.stem for p in Path(verification.__file__).parent.glob("rows_*.py"))


def test_every_topic_module_is_read_by_the_table():
    declared = [importlib.import_module(f"stereoplotter.verification.{t}").ROWS for t in TOPICS]
    assert TOPICS and all(any(rows is m for m in table.ROW_MODULES) for rows in declared)
    assert len(table.ROW_MODULES) == len(TOPICS)


def test_the_table_holds_its_47_rows_once_each():
    """Tables 19, 20, chapter 5 (13 rows) and (6.28)–(6.61) (34 rows), each identity once."""
    identities = [e.identity for e in table.row_entries(BOOK)]
    assert len(identities) == len(set(identities)) == 47
