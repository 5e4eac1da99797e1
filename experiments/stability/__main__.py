"""``python -m experiments.stability --out F [--quick]``."""

import sys

from experiments.stability import main

sys.exit(main())
