"""Instruments: the stateful virtual SC-1, SPR-3 and SD-3 — their kinematics, correction
principles, mechanics and error model.

The specification an instrument is built from (ranges, least counts, gear sets, each value
documented or assumed) is the layer below, :mod:`stereoplotter.spec`; see ``docs/instruments.md``.
"""
