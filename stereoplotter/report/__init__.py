"""What a user reads, rendered in memory: the setup sheet as Markdown, plain data and the PDF
form, a block's and a job's files, the simulation's transcript and summary, the verification
table, the error budget, a grade.

Layer: edge, beside :mod:`stereoplotter.plotting`, under :mod:`stereoplotter.commands`. Renders
only: functions return text or ``name → bytes``; reading and writing files is
:mod:`stereoplotter.io`'s, called by the commands (an import-linter contract).
"""
