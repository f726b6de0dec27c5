"""What BehaviorTree.CPP accepts: the name rules, the workspace context, the semantic rule
families, each with the diagnostic codes it defines, and the registry of all codes
(:mod:`bt_lsp.rules.registry`). Imports :mod:`bt_lsp.syntax` only."""
