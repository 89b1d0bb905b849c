"""Figures. The only package that imports matplotlib (non-interactive Agg back-end).

Layer: edge. May import every layer below; nothing below imports it. Every function returns a
matplotlib Figure; writing it is the caller's business (``report``, ``cli``).

* :mod:`.figures` — the scenario layout, the setup sheet, the residual y-parallax of a run;
* :mod:`.accuracy` — error maps, the verification chart, Monte Carlo histograms;
* :mod:`.evaluation` — the parallax-error map of an evaluated model.
"""
