"""``python -m fabricate``."""

from __future__ import annotations

import sys

from fabricate.cli import main

sys.exit(main())
