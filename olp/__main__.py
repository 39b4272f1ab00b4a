"""``python -m olp`` is the ``olp`` command."""

import sys

from olp.cli import main

sys.exit(main())
