"""orbed.bus: publish and subscribe over LCM's UDP multicast protocol as LCM 1.3's C library speaks
it, written here because Debian's LCM has no Python binding.

    bus = orbed.bus.Bus()                        # $ORBED_LCM_URL, else udpm://239.255.76.67:7667?ttl=0
    bus.subscribe("IIWA_STATUS", orbed_lcm.iiwa_status_t, lambda channel, msg: ...)
    bus.publish("IIWA_COMMAND", command)         # a generated message, or bytes
    bus.handle(timeout_s=1.0)                    # the next message to its callbacks; 0 on timeout

The wire (big-endian): a message whose channel, NUL and payload fit in 65 499 bytes is one datagram,
LC02 magic 0x4C433032 | uint32 sequence number | channel | NUL | payload. A larger one is
fragmented, each datagram LC03 magic 0x4C433033 | uint32 sequence number | uint32 payload size |
uint32 offset of this fragment's data in the payload | uint16 fragment number | uint16 fragments;
fragment 0 then holds channel | NUL and the first 65 487 - (channel + 1) payload bytes, the others up
to 65 487 payload bytes each. One sequence number per message, counting up per sender. Channel
names are at most 63 bytes. Sent to the group and port of the URL with the URL's ttl (orbed uses 0:
nothing leaves the host; scripts/netns-exec gives each run its own namespace).

Bounds: a fragmented message larger than max_message_bytes (16 MiB) is refused from its first
fragment; a partial message holds the bytes that arrived (counted with CHUNK_OVERHEAD_BYTES per
fragment), not the size its header claims; at most max_partials (8) messages are reassembled at
once, holding at most max_partial_bytes (32 MiB) together: the oldest are dropped to make room. Fragments that do not tile their message exactly
(overlaps, holes) are refused when the last one arrives. A message for a typed subscription is
walked (orbed.wire) before it is decoded. Every refusal is counted in `refused` under a key, as the
C++ processes count theirs in PROCESS_STATUS: "bus/<reason>" for datagrams, "<channel>/decode/<kind>"
for messages, "<channel>/handler" for a callback that raised; and logged (the first of a key, then
every 1000th). At most 64 keys, further ones under "other".

Threading: none; call handle() from one thread. publish() may be called from any thread.
"""
import collections
import logging
import os
import re
import select
import socket
import struct
import threading
import time
import urllib.parse

from orbed import types, wire

DEFAULT_URL = "udpm://239.255.76.67:7667?ttl=0"
SHORT_MAGIC = 0x4C433032     # "LC02"
FRAGMENT_MAGIC = 0x4C433033  # "LC03"
SHORT_HEADER = struct.Struct(">II")
FRAGMENT_HEADER = struct.Struct(">IIIIHH")
SHORT_MESSAGE_MAX_BYTES = 65499  # channel + NUL + payload in one LC02 datagram
FRAGMENT_MAX_PAYLOAD = 65487     # bytes after the LC03 header in one datagram
MAX_CHANNEL_BYTES = 63
MAX_REFUSAL_KEYS = 64
DEFAULT_RECV_BUF_BYTES = 8 << 20
CHUNK_OVERHEAD_BYTES = 160  # what Python holds per kept fragment beside its bytes, counted against the bounds  # asked of the kernel (SO_RCVBUF) unless the URL says recv_buf_size

log = logging.getLogger("orbed.bus")


def default_url():
    """The URL orbed's processes use: $ORBED_LCM_URL, else $LCM_DEFAULT_URL, else DEFAULT_URL."""
    return os.environ.get("ORBED_LCM_URL") or os.environ.get("LCM_DEFAULT_URL") or DEFAULT_URL


def parse_url(url):
    """(group, port, ttl, recv_buf_size or None) of a udpm:// URL."""
    parts = urllib.parse.urlsplit(url)
    if parts.scheme != "udpm":
        raise ValueError(f"{url}: only udpm:// URLs are supported")
    host, _, port = parts.netloc.partition(":")
    options = dict(urllib.parse.parse_qsl(parts.query))
    unknown = set(options) - {"ttl", "recv_buf_size"}
    if unknown:
        raise ValueError(f"{url}: unknown option(s) {sorted(unknown)}")
    recv = options.get("recv_buf_size")
    return (host or "239.255.76.67", int(port or 7667), int(options.get("ttl", 0)),
            int(recv) if recv else None)


def encode_datagrams(channel, payload, seqno):
    """The datagrams LCM's C library sends for one message."""
    name = channel.encode()
    if len(name) > MAX_CHANNEL_BYTES or b"\0" in name:
        raise ValueError(f"channel name {channel!r}: at most {MAX_CHANNEL_BYTES} bytes, no NUL")
    seqno &= 0xFFFFFFFF
    head = name + b"\0"
    if len(head) + len(payload) <= SHORT_MESSAGE_MAX_BYTES:
        return [SHORT_HEADER.pack(SHORT_MAGIC, seqno) + head + payload]
    total = len(head) + len(payload)
    fragments = -(-total // FRAGMENT_MAX_PAYLOAD)
    if fragments > 65535:
        raise ValueError(f"message of {len(payload)} bytes: too large for LCM")
    first = FRAGMENT_MAX_PAYLOAD - len(head)
    out = [FRAGMENT_HEADER.pack(FRAGMENT_MAGIC, seqno, len(payload), 0, 0, fragments) + head + payload[:first]]
    offset = first
    for number in range(1, fragments):
        chunk = payload[offset:offset + FRAGMENT_MAX_PAYLOAD]
        out.append(FRAGMENT_HEADER.pack(FRAGMENT_MAGIC, seqno, len(payload), offset, number, fragments) + chunk)
        offset += len(chunk)
    return out


class _Partial:
    """A message being reassembled: its fragments as they came (memory = the bytes received, not
    the size a header claims)."""
    __slots__ = ("size", "fragments", "chunks", "bytes", "channel")

    def __init__(self, size, fragments):
        self.size, self.fragments = size, fragments
        self.chunks = {}  # fragment number -> (offset, bytes)
        self.bytes = 0  # the chunks' bytes and their overhead
        self.channel = None

    def assemble(self):
        """The payload, or None unless the fragments tile it exactly."""
        at, parts = 0, []
        for offset, chunk in sorted(self.chunks.values(), key=lambda c: c[0]):
            if offset != at:
                return None
            parts.append(chunk)
            at += len(chunk)
        return b"".join(parts) if at == self.size else None


class Reassembler:
    """Datagrams in, whole (channel, payload) messages out, with the bounds of the module doc.
    refusal(reason) is called for every refused datagram or dropped partial. Pure (no sockets)."""

    def __init__(self, refusal, max_message_bytes=16 << 20, max_partials=8, max_partial_bytes=32 << 20):
        self.refusal = refusal
        self.max_message_bytes = min(max_message_bytes, max_partial_bytes)
        self.max_partials = max_partials
        self.max_partial_bytes = max_partial_bytes
        self.partials = collections.OrderedDict()  # (sender, seqno) -> _Partial, oldest first
        self.partial_bytes = 0  # the buffers of self.partials together

    @staticmethod
    def _channel(data, start):
        end = data.find(b"\0", start, start + MAX_CHANNEL_BYTES + 1)
        if end < 0:
            return None, None
        try:
            return data[start:end].decode(), end + 1
        except UnicodeDecodeError:
            return None, None

    def _drop(self, key):
        self.partial_bytes -= self.partials.pop(key).bytes

    def feed(self, data, sender):
        """The message `data` completes, as (channel, payload bytes), or None."""
        if len(data) < SHORT_HEADER.size:
            return self.refusal("short_datagram")
        magic = SHORT_HEADER.unpack_from(data)[0]
        if magic == SHORT_MAGIC:
            channel, start = self._channel(data, SHORT_HEADER.size)
            if channel is None:
                return self.refusal("channel")
            return channel, bytes(data[start:])
        if magic != FRAGMENT_MAGIC:
            return self.refusal("magic")
        if len(data) < FRAGMENT_HEADER.size:
            return self.refusal("fragment_header")
        _, seqno, size, offset, number, fragments = FRAGMENT_HEADER.unpack_from(data)
        if fragments == 0 or number >= fragments:
            return self.refusal("fragment_header")
        if size > self.max_message_bytes:
            return self.refusal("too_large")
        start = FRAGMENT_HEADER.size
        channel = None
        if number == 0:
            channel, start = self._channel(data, start)
            if channel is None:
                return self.refusal("channel")
        chunk = memoryview(data)[start:]
        key = (sender, seqno)
        partial = self.partials.get(key)
        if partial is not None and (partial.size != size or partial.fragments != fragments):
            self._drop(key)
            self.refusal("fragment_mismatch")
            partial = None
        if offset + len(chunk) > size:
            if partial is not None:
                self._drop(key)
            return self.refusal("fragment_range")
        if partial is not None and number in partial.chunks:
            return self.refusal("fragment_duplicate")
        # Room for this fragment: the oldest other partial messages are dropped.
        while any(k != key for k in self.partials) and (
                (partial is None and len(self.partials) >= self.max_partials) or
                self.partial_bytes + len(chunk) + CHUNK_OVERHEAD_BYTES > self.max_partial_bytes):
            self._drop(next(k for k in self.partials if k != key))
            self.refusal("partial_evicted")
        if partial is None:
            partial = self.partials[key] = _Partial(size, fragments)
        partial.chunks[number] = (offset, bytes(chunk))
        partial.bytes += len(chunk) + CHUNK_OVERHEAD_BYTES
        self.partial_bytes += len(chunk) + CHUNK_OVERHEAD_BYTES
        if channel is not None:
            partial.channel = channel
        if len(partial.chunks) < fragments:
            return None
        self._drop(key)
        payload = partial.assemble()
        if payload is None or partial.channel is None:
            return self.refusal("fragment_range")
        return partial.channel, payload


class Subscription:
    def __init__(self, pattern, message_type, callback):
        self.pattern = re.compile(pattern)
        self.message_type = message_type
        self.callback = callback


class Bus:
    """One LCM endpoint: a send socket now, a receive socket joined to the group at the first
    subscribe (as LCM does). See the module doc."""

    def __init__(self, url=None, max_message_bytes=16 << 20, max_partials=8, max_partial_bytes=32 << 20):
        self.url = url or default_url()
        self.group, self.port, self.ttl, self.recv_buf_size = parse_url(self.url)
        self.refused = collections.Counter()
        self.received = 0  # whole messages on a subscribed channel (before decoding)
        self.published = 0
        self._started = time.monotonic()
        self._reassembler = Reassembler(lambda reason: self._refuse("bus/" + reason), max_message_bytes,
                                        max_partials, max_partial_bytes)
        self._subscriptions = []
        self._seqno = 0
        self._send_lock = threading.Lock()
        self._send = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self._send.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_TTL, self.ttl)
        self._send.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_LOOP, 1)
        self._recv = None

    def _refuse(self, key, why=""):
        if key not in self.refused and len(self.refused) >= MAX_REFUSAL_KEYS:
            key = "other"
        self.refused[key] += 1
        n = self.refused[key]
        if n == 1 or n % 1000 == 0:
            log.warning("refused %s (%d so far)%s", key, n, ": " + why if why else "")
        return None

    def _open_receive(self):
        if self._recv is not None:
            return
        s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        s.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        s.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, self.recv_buf_size or DEFAULT_RECV_BUF_BYTES)
        s.bind((self.group, self.port))
        membership = socket.inet_aton(self.group) + socket.inet_aton("0.0.0.0")
        s.setsockopt(socket.IPPROTO_IP, socket.IP_ADD_MEMBERSHIP, membership)
        s.setblocking(False)
        self._recv = s

    def subscribe(self, channel, message_type, callback):
        """Calls callback(channel, message) for every message on a channel whose whole name matches
        the regular expression `channel` (as LCM's subscribe does). message_type: a generated class
        (the message is walked, then decoded; refusals counted) or None (the payload bytes)."""
        self._open_receive()
        subscription = Subscription(channel, message_type, callback)
        self._subscriptions.append(subscription)
        return subscription

    def unsubscribe(self, subscription):
        self._subscriptions.remove(subscription)

    def publish(self, channel, message):
        """Sends a generated message (its encode()) or bytes on `channel`."""
        payload = message if isinstance(message, (bytes, bytearray, memoryview)) else message.encode()
        with self._send_lock:
            datagrams = encode_datagrams(channel, bytes(payload), self._seqno)
            self._seqno = (self._seqno + 1) & 0xFFFFFFFF
            for datagram in datagrams:
                self._send.sendto(datagram, (self.group, self.port))
            self.published += 1

    def status(self, name, state=None):
        """This endpoint's heartbeat as orbed's processes send theirs on PROCESS_STATUS (1 Hz): name,
        pid, host, uptime, messages in and out, and the refusals by key (state: RUNNING unless given).
        Publish it with bus.publish("PROCESS_STATUS", bus.status("my-client"))."""
        m = types.lcm_types().process_status_t()
        m.utime, m.name, m.pid, m.host = int(time.time() * 1e6), name, os.getpid(), socket.gethostname()
        m.state = m.STATE_RUNNING if state is None else state
        m.uptime_s, m.messages_in, m.messages_out = time.monotonic() - self._started, self.received, self.published
        m.reject_reason = sorted(self.refused)
        m.reject_count = [self.refused[k] for k in m.reject_reason]
        m.num_reasons, m.rejected_inputs = len(m.reject_reason), sum(self.refused.values())
        m.last_error, m.drop_reason, m.drop_count = "", [], []
        return m

    def fileno(self):
        """The receive socket's descriptor (for select); subscribes first."""
        self._open_receive()
        return self._recv.fileno()

    def handle(self, timeout_s=None):
        """Receives until one message has been dispatched (its callbacks run) or timeout_s passes
        (None: no limit); returns the callbacks run, 0 on timeout. One message per call, as LCM's
        handle(): what arrives meanwhile waits in the socket for the next call."""
        self._open_receive()
        deadline = None if timeout_s is None else time.monotonic() + timeout_s
        while True:
            try:
                data, sender = self._recv.recvfrom(65536)
            except BlockingIOError:
                wait = None if deadline is None else deadline - time.monotonic()
                if wait is not None and wait <= 0:
                    return 0
                select.select([self._recv], [], [], wait)
                continue
            dispatched = self.feed(data, sender)
            if dispatched:
                return dispatched
            if deadline is not None and time.monotonic() >= deadline:
                return 0

    def handle_until(self, done, timeout_s):
        """Handles messages until done() is true or timeout_s passes; returns done()."""
        deadline = time.monotonic() + timeout_s
        while not done():
            left = deadline - time.monotonic()
            if left <= 0:
                break
            self.handle(left)
        return done()

    def feed(self, datagram, sender=("127.0.0.1", 0)):
        """Processes one datagram as if it had arrived from `sender`; returns the callbacks run."""
        whole = self._reassembler.feed(datagram, sender)
        return 0 if whole is None else self._dispatch(*whole)

    def _dispatch(self, channel, payload):
        n, matched = 0, False
        for s in list(self._subscriptions):
            if not s.pattern.fullmatch(channel):
                continue
            if not matched:
                self.received, matched = self.received + 1, True
            message = payload
            if s.message_type is not None:
                try:
                    message = wire.decode(s.message_type, payload)
                except wire.WireError as e:
                    self._refuse(f"{channel}/decode/{e.kind}", str(e))
                    continue
            try:
                s.callback(channel, message)
                n += 1
            except Exception as e:  # a callback's bug is counted and logged; the bus keeps running
                self._refuse(f"{channel}/handler", f"exception: {e!r}")
        return n

    def close(self):
        for s in (self._send, self._recv):
            if s is not None:
                s.close()
        self._recv = None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
