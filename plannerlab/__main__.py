"""`python -m plannerlab`: the plannerlab command."""

import sys

from plannerlab.cli.main import main

sys.exit(main())
