"""``python -m scenegen.cli VERB ...``: the same as the ``scenegen`` console script."""

from __future__ import annotations

import sys

from scenegen.cli import main

if __name__ == "__main__":
    sys.exit(main())
