"""``python -m femmech`` is the ``femmech`` command (see :mod:`femmech.cli`).

Stage 10: imports only femmech.cli.
"""

import sys

from femmech.cli import main

sys.exit(main())
