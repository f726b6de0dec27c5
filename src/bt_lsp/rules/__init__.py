"""What BehaviorTree.CPP accepts: the diagnostic codes, the name rules, the workspace
context and the semantic rule families. Imports :mod:`bt_lsp.syntax` only."""
