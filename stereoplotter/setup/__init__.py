"""The setup-data computer (Table 24, Eqs. (6.1)–(6.18) of Kushtin & Lyskov 1984, §26).

Layer: pure. May import :mod:`stereoplotter.geometry`, :mod:`stereoplotter.geodesy`,
:mod:`stereoplotter.scenario`, the instrument *specification* (:mod:`stereoplotter.spec`, data
and range checks only) and the base modules (``constants``, ``errors``). Never imports
:mod:`stereoplotter.instrument` (the stateful virtual instrument: an import-linter contract),
the procedures, files (``io``), reports or plots.

* :mod:`.equations` — Eqs. (6.3)–(6.15), one function each, vectorised;
* :mod:`.scale_choice` — the choice of M_г, M_в within the instrument's ranges;
* :mod:`.readings` — the counter readings of the five stages, Eqs. (6.9)–(6.18);
* :mod:`.sheet` — the setup sheet of one stereopair;
* :mod:`.block` — the same for N stereopairs at once.
"""
