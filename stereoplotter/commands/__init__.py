"""The commands: one module per command of ``stereoplotter`` (the layer between the CLI and the
web, above, and the report, plotting and io packages with the library, below).

Each command module defines

* ``add_arguments(sub)``: adds its sub-parser(s) with ``sub.add_parser(...)`` and
  ``set_defaults(func=run)`` (or one function per sub-command);
* ``run(args) -> int``: load (:mod:`stereoplotter.io`) → run (the library) → render
  (:mod:`stereoplotter.report`, :mod:`stereoplotter.plotting`) → write (:mod:`stereoplotter.io`),
  returning the exit code.

A command module imports only :mod:`argparse` and :mod:`.arguments` at its top; the library
comes in inside ``run`` (or in a work module ``run`` imports: :mod:`.simulation`,
:mod:`.verification`, :mod:`.error_budget`, :mod:`.setup_job`, :mod:`.setup_block`), so
building the parser loads no scipy, matplotlib, pydantic model or web server. The command
modules are listed once, in :data:`stereoplotter.cli.COMMANDS`.
"""
