"""The first page of the form of pair 101-102 for docs/production.md.

Run from the repository root: ``python docs/make_form_figure.py`` (needs the ``docs`` extra:
pypdfium2 renders the PDF); writes docs/img/form-page1.png. It runs
``stereoplotter setup jobs/strip8/job.yaml --lang ru`` into a temporary folder and renders page 1
of ``101-102/sheet.pdf`` at 100 dpi.
"""

from __future__ import annotations

import subprocess
import sys
import tempfile
from pathlib import Path

import pypdfium2

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "docs" / "img" / "form-page1.png"


def main() -> None:
    with tempfile.TemporaryDirectory() as tmp:
        job = ROOT / "jobs" / "strip8" / "job.yaml"
        cmd = [sys.executable, "-m", "stereoplotter", "setup", str(job), "--lang", "ru"]
        subprocess.run([*cmd, "-o", tmp], check=True, capture_output=True)
        pdf = pypdfium2.PdfDocument(str(Path(tmp) / "101-102" / "sheet.pdf"))
        image = pdf[0].render(scale=100 / 72).to_pil()
        image.save(OUT, optimize=True)
    print(f"wrote {OUT.relative_to(ROOT)} ({image.width} x {image.height} px)")


if __name__ == "__main__":
    main()
