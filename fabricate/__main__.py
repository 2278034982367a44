"""``python -m fabricate``."""

from __future__ import annotations

import sys

from fabricate.cli import main

if __name__ == "__main__":  # a spawned worker process (Dask, multiprocessing) may import this module
    sys.exit(main())
