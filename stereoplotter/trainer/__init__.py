"""The trainer core: exercises, a trainee's session on the virtual instrument, grading.

Layer: orchestration (beside ``verification``). May import ``procedure``, ``setup``,
``instrument``, ``scenario``, ``imagery`` and the pure layers; never ``io``, ``report``,
``plotting`` or ``web``. Exercise files are read by ``io``.
"""
