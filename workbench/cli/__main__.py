"""``python -m workbench.cli …``: the ``workbench`` command. Importing the module (as the API
docs do when they list the package's modules) runs nothing."""

import sys

from . import main

if __name__ == "__main__":
    sys.exit(main())
