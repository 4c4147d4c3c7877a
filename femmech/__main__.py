"""``python -m femmech`` is the ``femmech`` command (see :mod:`femmech.cli`)."""

import sys

from femmech.cli import main

sys.exit(main())
