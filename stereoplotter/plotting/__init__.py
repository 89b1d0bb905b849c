"""Figures. The only package that imports matplotlib (non-interactive Agg back-end).

Layer: edge, beside :mod:`stereoplotter.report`, under :mod:`stereoplotter.commands`. Every
drawing function returns a matplotlib Figure; :func:`.encode.figure_bytes` is the one encoder
(PNG or PDF bytes; the ``*_png`` functions of :mod:`.triangulation` call it); writing them is
:mod:`stereoplotter.io`'s, called by the commands.

* :mod:`.figures` — the scenario layout, the setup sheet, the residual y-parallax of a run;
* :mod:`.accuracy` — error maps, the verification chart, Monte Carlo histograms;
* :mod:`.evaluation` — the parallax-error map of an evaluated model;
* :mod:`.budget` — the bar chart of an error budget;
* :mod:`.study` — the maps, lines and categories of a study report;
* :mod:`.triangulation` — the residuals and precision of a triangulated block;
* :mod:`.encode` — a figure as PNG or PDF bytes, reproducibly.
"""
