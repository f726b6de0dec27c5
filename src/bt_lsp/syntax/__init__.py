"""The text of a document and what it says, read as BehaviorTree.CPP reads it: line
index, tokens, the BT model of elements and names, text edits. Imports nothing else of
bt_lsp."""
