"""Editing features over the rules' results: definitions, references, renames, symbols,
folding, completion, hover and fixes. Pure: returns data and edits, applies nothing."""
