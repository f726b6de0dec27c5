"""bt-lsp: a language server and checker for BehaviorTree.CPP XML."""

__version__ = "0.1.0"
