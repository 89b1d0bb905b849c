"""`stereoplotter render`: the files it writes decode to the arrays the library renders."""

from __future__ import annotations

import io

import numpy as np
from PIL import Image

from stereoplotter.cli import main
from stereoplotter.imagery.photo import render_photo
from stereoplotter.io.scenario_file import load_scenario


def test_render_writes_photo_and_views(tmp_path):
    assert main(["render", "pair60", "--side", "left", "--pixel", "0.4", "-o", str(tmp_path)]) == 0
    assert sorted(p.name for p in tmp_path.iterdir()) == ["photo_left.png", "view_left.png"]
    decoded = np.asarray(Image.open(io.BytesIO((tmp_path / "photo_left.png").read_bytes())))
    expected = render_photo(load_scenario("pair60"), "left", pixel_mm=0.4).image
    np.testing.assert_array_equal(decoded, expected)
    view = np.asarray(Image.open(tmp_path / "view_left.png"))
    assert view.shape == (256, 256) and view.std() > 5


def test_render_refuses_magnification_beyond_the_stop(tmp_path, capsys):
    try:
        main(["render", "pair60", "--magnification", "100", "-o", str(tmp_path)])
    except SystemExit as exc:
        assert exc.code == 2
    assert "expected a number in [0.5, 60]" in capsys.readouterr().err
