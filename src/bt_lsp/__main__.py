"""``python -m bt_lsp`` is the same as the ``bt-lsp`` command."""

import sys

from bt_lsp.cli.main import main

sys.exit(main())
