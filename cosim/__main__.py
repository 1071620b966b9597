"""``python -m cosim`` is the same as the ``cosim`` console script."""

from cosim.cli.main import main

raise SystemExit(main())
