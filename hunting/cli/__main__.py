"""``python -m hunting.cli``: the same as the ``hunting`` command."""
import sys

from . import main

sys.exit(main())
