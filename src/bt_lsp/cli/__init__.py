"""The command line: ``bt-lsp check`` and its output formats, over the same engine."""
