import sys

from spatter_read import cli

sys.exit(cli())
