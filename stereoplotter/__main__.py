"""``python -m stereoplotter``: the same as the ``stereoplotter`` command."""

from stereoplotter.cli import main

raise SystemExit(main())
