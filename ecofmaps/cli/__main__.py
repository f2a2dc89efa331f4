"""``python -m ecofmaps.cli``: the ``ecofmaps`` command."""

import sys

from ecofmaps.cli.main import main

if __name__ == "__main__":
    sys.exit(main())
