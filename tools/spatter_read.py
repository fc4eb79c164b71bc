#!/usr/bin/env python3
"""The `spatter-read` command from a checkout, without installing the package:
python/spatter_read (`pip install ./python` installs it with its command)."""
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "python"))

from spatter_read import main  # noqa: E402

if __name__ == "__main__":
    sys.exit(main(sys.argv))
