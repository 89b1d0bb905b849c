"""Accuracy formulas of model building, Kushtin & Lyskov 1984, ch. 5 §22–§24 and ch. 6 §27.

Layer: pure. Formulas only — book and rigorous form of each — in :mod:`.chapter5` and
:mod:`.setup_accuracy`; imports numpy and the base modules, nothing else of the package. Their
Monte Carlo verification is :mod:`stereoplotter.verification`.
"""
