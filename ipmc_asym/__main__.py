import sys

from ipmc_asym.cli import main

sys.exit(main())
