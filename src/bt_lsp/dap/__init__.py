"""A Debug Adapter (Debug Adapter Protocol) for a running BehaviorTree.CPP tree.

``bt-lsp debug-adapter`` lets an editor's debugger attach to an executor's Groot2
publisher: breakpoints on the lines of a tree file, the tree stopped before that node
ticks, its blackboards as variables, continue, and the node forced to succeed or fail.

``framing`` (Content-Length frames, bounded), ``messages`` (DAP requests, responses and
events as JSON values), ``nodemap`` (a file's lines to the running tree's uids),
``values`` (blackboard values as DAP variables), ``session`` (what each request does,
against an executor link) and ``adapter`` (stdio, a reader thread and the loop).  Only
``adapter`` makes the ZeroMQ client (pyzmq, the ``live`` extra).
"""
