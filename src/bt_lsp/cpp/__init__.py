"""The node catalog as the project's C++ declares it, read with tree-sitter.

Pure: it parses text it is given and never touches the file system (discovery and the
on-disk cache are in :mod:`bt_lsp.project.cpp_scan`).  :mod:`.extract` turns one file into
:class:`~bt_lsp.cpp.facts.FileFacts` (cacheable plain data); :mod:`.catalog` links the facts
of many files into :class:`~bt_lsp.cpp.catalog.CppNode` entries, each saying by flags what
a static reading could not know.
"""
