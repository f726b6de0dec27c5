"""A pygls server that does nothing: the floor for bt-lsp's start-up time."""

from pygls.lsp.server import LanguageServer

if __name__ == "__main__":
    LanguageServer("bare", "0").start_io()
