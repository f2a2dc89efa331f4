"""``python -m ecofmaps.cli``: the ``ecofmaps`` command."""

import sys

from ecofmaps.cli.main import main

sys.exit(main())
