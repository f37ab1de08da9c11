"""``python -m designer.cli``: the fpdesign command."""

import sys

from designer.cli import main

sys.exit(main())
