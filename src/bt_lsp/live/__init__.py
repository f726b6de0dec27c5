"""Watching a running tree: BehaviorTree.CPP's Groot2 protocol and its .btlog files.

``protocol`` (wire format, pure), ``msgpack`` (blackboard dumps), ``tree`` (the running
tree's XML), ``btlog`` (FileLogger2 files), ``view`` (text drawing) and ``client`` (the
ZeroMQ client; needs pyzmq, the ``live`` extra: ``pip install 'bt-lsp[live]'``).  Only
``client`` imports zmq, so reading logs works without it.
"""
