"""The ``plannerlab`` command: one module per subcommand, argument parsing and printing only.

:func:`main` (in :mod:`plannerlab.cli.main`) builds the parser from each subcommand
module's ``add_parser`` and turns a :class:`~plannerlab.errors.PlannerlabError` into
``error: …`` on stderr and exit code 2.
"""

from plannerlab.cli.main import main

__all__ = ["main"]
