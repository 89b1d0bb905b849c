"""What a user reads: the setup sheet as YAML, Markdown and PDF, the simulation's transcript and
summary, the verification table.

Layer: edge. May import every layer below and :mod:`stereoplotter.plotting` and
:mod:`stereoplotter.io` (to write files); nothing below imports it.
"""
