"""Every file the program reads or writes: input files (scenarios, instruments, blocks, injected
errors, geometry), where the shipped and the user's data are found, atomic writes, the per-trial
spool of long runs.

Layer: edge. May import every layer below (pure, instrument, procedure, verification); nothing
below imports it. YAML is parsed only here.
"""
