"""``stereoplotter budget``: the JSON lists every term with its three contributions and validates
against the published schema; the three instruments run; bad input gives one clear line."""

from __future__ import annotations

import json
from pathlib import Path

import jsonschema
import pytest

from stereoplotter.cli import main
from stereoplotter.instrument.error_model import error_model_from_spec
from stereoplotter.io.instrument_file import load_instrument
from stereoplotter.verification.budget import MEASURES, OPERATOR_TERMS

SCHEMA = Path(__file__).resolve().parents[2] / "docs" / "schemas" / "budget.schema.json"


@pytest.mark.parametrize("instrument", ["sc1", "spr3", "sd3"])
def test_budget_json_lists_every_term_and_validates(instrument, capsys, tmp_path):
    code = main(
        ["budget", "pair60", "--instrument", instrument, "--trials", "3", "--json", "-q"]
        + ["-o", str(tmp_path)]
    )
    printed = capsys.readouterr().out
    out = json.loads(printed)
    assert code == 0
    assert sorted(p.name for p in tmp_path.iterdir()) == ["budget.json", "budget.md", "budget.png"]
    assert (tmp_path / "budget.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert (tmp_path / "budget.json").read_text(encoding="utf-8") == printed
    md = (tmp_path / "budget.md").read_text(encoding="utf-8")
    assert "| `zero_reading.dx_left` |" in md and md.count("\n### ") == len(MEASURES)
    validator = jsonschema.Draft202012Validator(json.loads(SCHEMA.read_text(encoding="utf-8")))
    assert [e.message for e in validator.iter_errors(out)] == []
    names = [r["name"] for r in out["terms"]]
    spec = load_instrument(instrument)
    assert names == [*error_model_from_spec(spec).names, *OPERATOR_TERMS, "operator.rounding"]
    for r in out["terms"]:
        for kind in ("one_at_a_time", "all_but_one"):
            for m in MEASURES:
                assert set(r[kind][m]) == {"rms", "se", "delta_ms", "delta_ms_se"}
        assert set(r["linear"]) == set(MEASURES)
    assert out["instrument"] == instrument and out["trials"] == 3


@pytest.mark.parametrize(
    ("args", "words"),
    [
        (["pair60", "--instrument", "sc9"], ["sc9", "no such instrument", "did you mean sc1"]),
        (["pair99", "--instrument", "sc1"], ["pair99", "no such scenario"]),
        (["pair60", "--instrument", "sc1", "--trials", "1"], ["--trials", "found 1"]),
    ],
)
def test_bad_input_is_one_line(args, words, capsys):
    try:
        code = main(["budget", *args, "-q"])
    except SystemExit as exc:  # a usage error (argparse): exit code 2
        code = exc.code
    err = capsys.readouterr().err
    assert code in (1, 2)
    assert err.count("\n") == 1 and err.startswith("error: ")
    for w in words:
        assert w in err
