"""``python -m olp`` is the ``olp`` command.

``python -m`` puts the working directory first on ``sys.path``, so a stray ``numpy.py`` or
``yaml.py`` in the folder of a cloned robot project would be imported instead of the real
package. olp's own modules are found through the package itself; the working directory is
dropped before anything else is imported (the ``olp`` console script never had it).
"""

import os
import sys

_cwd = os.getcwd()
sys.path[:] = [p for p in sys.path if p not in ("", ".") and os.path.abspath(p) != _cwd]

from olp.cli import main  # noqa: E402

sys.exit(main())
