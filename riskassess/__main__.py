import sys

from riskassess.cli import main

sys.exit(main())
