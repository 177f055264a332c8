"""``python -m drake_traj.cli``: the same as ``drake-traj``."""

import sys

from drake_traj.cli.parser import main

if __name__ == "__main__":
    sys.exit(main())
