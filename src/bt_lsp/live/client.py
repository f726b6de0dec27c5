"""A Groot2 client: talks to a running BehaviorTree.CPP executor's ``Groot2Publisher``.

The executor serves ZeroMQ REQ/REP on PORT and publishes breakpoint notifications on
PORT + 1; this client only connects (it never listens).  One request at a time: a REQ
socket that timed out is closed and replaced (ZeroMQ's REQ cannot send again before it
has received).  Not thread-safe: use one client per thread.

A restarted executor is detected two ways: the tree UUID in a reply changed, or the TCP
connection to the executor closed since the last reply (a ZeroMQ socket monitor sees it).
BehaviorTree.CPP 4.8.2 draws the UUID from a default-seeded generator, so every executor
run has the same one and only the second signal tells; later versions seed it randomly.
Either bumps :attr:`Groot2Client.generation`: read the tree again.

The executor releases a blocked breakpoint (as CONTINUE) and disables every hook when it
has heard nothing for 5 s (its ``max_heartbeat_delay``): :meth:`wait_breakpoint` keeps
polling while it waits.
"""

from __future__ import annotations

import random
import time
from collections.abc import Sequence
from typing import Any, Final

import zmq

from bt_lsp.live.protocol import (
    DEFAULT_HOST,
    DEFAULT_PORT,
    Hook,
    HookMode,
    LiveError,
    NodeState,
    NodeStatus,
    Position,
    ProtocolError,
    Reply,
    RequestHeader,
    RequestType,
    Resume,
    Transition,
    blackboard_payload,
    decode_blackboards,
    decode_hooks,
    decode_notification,
    decode_reply,
    decode_status,
    decode_timestamp,
    decode_transitions,
    hook_insert_payload,
    hook_remove_payload,
    recording_payload,
    unlock_payload,
)
from bt_lsp.live.tree import LiveTree, parse_tree_xml

DEFAULT_TIMEOUT: Final = 1.0
MAX_MESSAGE_BYTES: Final = 64 * 1024 * 1024
_EVENTS: Final = zmq.EVENT_CONNECTED | zmq.EVENT_DISCONNECTED
# The requests sent as a header alone (the executor ignores extra parts of these).
_BARE: Final = frozenset(
    {
        RequestType.FULLTREE,
        RequestType.STATUS,
        RequestType.HOOKS_DUMP,
        RequestType.REMOVE_ALL_HOOKS,
        RequestType.DISABLE_ALL_HOOKS,
        RequestType.GET_TRANSITIONS,
    }
)


class Timeout(LiveError):
    """No answer in time (no executor on that port, or it hangs)."""


class ConnectionLost(LiveError):
    """The executor closed the connection while a request waited (it stopped or crashed)."""


class Groot2Client:
    """One executor's Groot2 server, at ``host:port``."""

    def __init__(
        self,
        host: str = DEFAULT_HOST,
        port: int = DEFAULT_PORT,
        *,
        timeout: float = DEFAULT_TIMEOUT,
        max_message_bytes: int = MAX_MESSAGE_BYTES,
    ) -> None:
        if not 1 <= port <= 65534:
            raise ValueError(f"port {port} is not in 1..65534 (the publisher uses port + 1)")
        if timeout <= 0:
            raise ValueError("the timeout must be positive")
        self.host = host
        self.port = port
        self.timeout = timeout
        self.max_message_bytes = max_message_bytes
        self.uuid: bytes | None = None
        self.generation = 0
        self._random = random.Random()
        self._dropped = False
        self._context = zmq.Context()
        self._req: zmq.Socket[bytes] | None = None
        self._monitor: zmq.Socket[bytes] | None = None
        self._sub: zmq.Socket[bytes] | None = None
        self._sub_monitor: zmq.Socket[bytes] | None = None
        self._sub_up = False
        self._open_req()

    # ------------------------------------------------------------------ sockets

    def _url(self, port: int) -> str:
        host = f"[{self.host}]" if ":" in self.host else self.host
        return f"tcp://{host}:{port}"

    def _socket(self, kind: int) -> zmq.Socket[bytes]:
        sock = self._context.socket(kind)
        sock.setsockopt(zmq.LINGER, 0)
        sock.setsockopt(zmq.MAXMSGSIZE, self.max_message_bytes)
        if ":" in self.host:
            sock.setsockopt(zmq.IPV6, 1)
        return sock

    def _open_req(self) -> None:
        self._req = self._socket(zmq.REQ)
        self._monitor = self._req.get_monitor_socket(_EVENTS)
        self._req.connect(self._url(self.port))

    def _close_req(self) -> None:
        if self._req is not None:
            self._drain_monitor()
            self._req.disable_monitor()
            self._req.close(0)
        if self._monitor is not None:
            self._monitor.close(0)
        self._req = self._monitor = None

    def _drain_monitor(self) -> bool:
        """Note a closed connection; True when one was seen now."""
        seen = False
        monitor = self._monitor
        while monitor is not None:
            try:
                frames = monitor.recv_multipart(zmq.NOBLOCK)
            except zmq.Again:
                break
            except zmq.ZMQError:
                break
            if len(frames) >= 1 and len(frames[0]) >= 2:
                event = int.from_bytes(frames[0][:2], "little")
                if event == zmq.EVENT_DISCONNECTED:
                    self._dropped = True
                    seen = True
        return seen

    def close(self) -> None:
        """Close the sockets (hooks stay in the executor: remove them first if needed)."""
        self._close_req()
        if self._sub is not None:
            self._sub.disable_monitor()
            self._sub.close(0)
            self._sub = None
        if self._sub_monitor is not None:
            self._sub_monitor.close(0)
            self._sub_monitor = None
        self._context.term()

    def __enter__(self) -> Groot2Client:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    # ------------------------------------------------------------------ requests

    def _request(self, kind: RequestType, payload: bytes | None = None) -> Reply:
        """Send one request and wait for its checked reply (Timeout, ConnectionLost,
        ExecutorError, ProtocolError).  Private: payloads come only from ``protocol``'s
        builders, through the typed methods below."""
        if kind is RequestType.BREAKPOINT_REACHED or (payload is None) != (kind in _BARE):
            raise ValueError(f"{kind.name} {'takes no' if kind in _BARE else 'needs a'} payload")
        if self._req is None:
            self._open_req()
        assert self._req is not None and self._monitor is not None
        header = RequestHeader(kind, self._random.getrandbits(32))
        parts = [header.encode()] if payload is None else [header.encode(), payload]
        self._drain_monitor()
        deadline = time.monotonic() + self.timeout
        try:
            self._req.send_multipart(parts, zmq.NOBLOCK)
        except zmq.ZMQError as e:  # nothing connected and nowhere to queue
            self._reset()
            raise Timeout(f"cannot send to {self._url(self.port)}: {e}") from None
        poller = zmq.Poller()
        poller.register(self._req, zmq.POLLIN)
        poller.register(self._monitor, zmq.POLLIN)
        while True:
            left = deadline - time.monotonic()
            if left <= 0:
                dropped = self._dropped
                self._reset()
                if dropped:
                    raise ConnectionLost(
                        f"{self._url(self.port)} closed the connection and did not answer "
                        f"again within {self.timeout:g} s"
                    )
                raise Timeout(f"no answer from {self._url(self.port)} within {self.timeout:g} s")
            ready = dict(poller.poll(max(1, int(left * 1000))))
            if self._monitor in ready and self._drain_monitor():
                self._reset()
                raise ConnectionLost(f"{self._url(self.port)} closed the connection")
            if self._req in ready:
                break
        raw = self._req.recv_multipart(copy=True)
        self._drain_monitor()
        reply = decode_reply(raw, header)
        if self.uuid is None or reply.uuid != self.uuid or self._dropped:
            self.generation += 1
            self.uuid = reply.uuid
            self._dropped = False
        return reply

    def _reset(self) -> None:
        self._close_req()
        self._open_req()

    def _body(self, reply: Reply, kind: RequestType) -> bytes:
        if len(reply.body) != 1:
            raise ProtocolError(f"{kind.name} answered {len(reply.body)} parts after the header")
        return reply.body[0]

    # ------------------------------------------------------------------ the API

    def read_tree(self) -> LiveTree:
        """FULLTREE: the running tree with every node's uid."""
        reply = self._request(RequestType.FULLTREE)
        return parse_tree_xml(self._body(reply, RequestType.FULLTREE))

    def status(self) -> dict[int, NodeState]:
        """STATUS: every node's current status, by uid."""
        return decode_status(self._body(self._request(RequestType.STATUS), RequestType.STATUS))

    def blackboards(self, names: Sequence[str]) -> dict[str, Any]:
        """BLACKBOARD: the entries of the named blackboards (``LiveTree.blackboards``);
        unknown names are left out of the answer."""
        reply = self._request(RequestType.BLACKBOARD, blackboard_payload(names))
        return decode_blackboards(self._body(reply, RequestType.BLACKBOARD))

    def insert_hooks(self, hooks: Hook | Sequence[Hook]) -> None:
        """HOOK_INSERT (a hook on an unknown uid is silently dropped by the executor)."""
        self._request(RequestType.HOOK_INSERT, hook_insert_payload(hooks))

    def set_breakpoint(self, uid: int, *, once: bool = False) -> None:
        """A PRE breakpoint: the tree stops before ticking node ``uid`` until unlocked."""
        self.insert_hooks(Hook(uid, Position.PRE, HookMode.BREAKPOINT, once=once))

    def replace(self, uid: int, result: NodeStatus, *, once: bool = False) -> None:
        """A REPLACE hook: node ``uid`` is not ticked and returns ``result`` instead."""
        self.insert_hooks(Hook(uid, Position.PRE, HookMode.REPLACE, once, True, result))

    def remove_hook(self, uid: int, position: Position = Position.PRE) -> None:
        """HOOK_REMOVE (releases the tree if it waits there); ExecutorError if none."""
        self._request(RequestType.HOOK_REMOVE, hook_remove_payload(uid, position))

    def hooks(self) -> list[Hook]:
        """HOOKS_DUMP: the hooks in place."""
        return decode_hooks(
            self._body(self._request(RequestType.HOOKS_DUMP), RequestType.HOOKS_DUMP)
        )

    def remove_all_hooks(self) -> None:
        self._request(RequestType.REMOVE_ALL_HOOKS)

    def disable_all_hooks(self) -> None:
        self._request(RequestType.DISABLE_ALL_HOOKS)

    def unlock(
        self,
        uid: int,
        result: Resume = Resume.CONTINUE,
        *,
        position: Position = Position.PRE,
        remove: bool = False,
    ) -> None:
        """BREAKPOINT_UNLOCK: let the tree go on from node ``uid``'s breakpoint: tick the
        node (CONTINUE) or make it return SUCCESS or FAILURE without ticking."""
        self._request(RequestType.BREAKPOINT_UNLOCK, unlock_payload(uid, result, position, remove))

    def start_recording(self) -> int:
        """TOGGLE_RECORDING start: the executor's clock (microseconds since the epoch)."""
        reply = self._request(RequestType.TOGGLE_RECORDING, recording_payload(True))
        return decode_timestamp(self._body(reply, RequestType.TOGGLE_RECORDING))

    def stop_recording(self) -> None:
        self._request(RequestType.TOGGLE_RECORDING, recording_payload(False))

    def transitions(self) -> list[Transition]:
        """GET_TRANSITIONS: what changed since the last call (the executor keeps 1000)."""
        reply = self._request(RequestType.GET_TRANSITIONS)
        return decode_transitions(self._body(reply, RequestType.GET_TRANSITIONS))

    # ------------------------------------------------------------------ notifications

    def subscribe(self) -> None:
        """Connect to the publisher (PORT + 1) now: a notification sent before the
        subscription is in place is lost (ZeroMQ PUB/SUB)."""
        if self._sub is None:
            self._sub = self._socket(zmq.SUB)
            self._sub.setsockopt(zmq.RCVHWM, 1000)
            self._sub.setsockopt(zmq.SUBSCRIBE, b"")
            self._sub_monitor = self._sub.get_monitor_socket(
                zmq.EVENT_HANDSHAKE_SUCCEEDED | zmq.EVENT_DISCONNECTED
            )
            self._sub.connect(self._url(self.port + 1))

    def publisher_connected(self) -> bool:
        """Whether the subscriber is connected to the publisher (PORT + 1) now: its
        handshake done, so the subscription follows on the same connection.  A
        breakpoint hit while it is not is stopped unseen."""
        self.subscribe()
        monitor = self._sub_monitor
        while monitor is not None:
            try:
                frames = monitor.recv_multipart(zmq.NOBLOCK)
            except zmq.ZMQError:
                break
            if frames and len(frames[0]) >= 2:
                event = int.from_bytes(frames[0][:2], "little")
                self._sub_up = event == zmq.EVENT_HANDSHAKE_SUCCEEDED
        return self._sub_up

    def poll_breakpoint(self, timeout: float) -> int | None:
        """The uid of a breakpoint notification received within ``timeout`` seconds, or
        None.  A malformed notification is consumed and raised as ProtocolError (the
        caller reports it).  No keepalive: the caller sends a request often enough."""
        self.subscribe()
        assert self._sub is not None
        if not self._sub.poll(max(0, int(timeout * 1000)), zmq.POLLIN):
            return None
        return decode_notification(self._sub.recv_multipart())

    def wait_breakpoint(self, timeout: float, *, keepalive: float = 1.0) -> int | None:
        """The uid of the next breakpoint reached, or None after ``timeout`` seconds.

        Polls STATUS every ``keepalive`` seconds meanwhile, so that the executor keeps
        its hooks enabled.  Malformed notifications are skipped."""
        self.subscribe()
        assert self._sub is not None
        deadline = time.monotonic() + timeout
        next_ping = time.monotonic() + keepalive
        while True:
            now = time.monotonic()
            if now >= deadline:
                return None
            if now >= next_ping:
                self.status()
                next_ping = time.monotonic() + keepalive
            wait = max(0.0, min(deadline, next_ping) - time.monotonic())
            if not self._sub.poll(max(1, int(wait * 1000)), zmq.POLLIN):
                continue
            parts = self._sub.recv_multipart()
            try:
                return decode_notification(parts)
            except LiveError:
                continue
