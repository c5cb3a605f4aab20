"""``python -m tiltlab.cli``: the ``tiltlab`` command."""

import sys

from . import main

sys.exit(main())
