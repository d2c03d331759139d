"""orbed.bus without processes: LCM's datagrams by hand (header layouts and sizes of LCM 1.3's
lcm_udpm.c), reassembly, and hostile datagrams and messages refused and counted."""
import struct
import time

import pytest

from orbed import bus, types, wire

lcm = types.lcm_types()


def status(num_joints=7):
    m = lcm.iiwa_status_t()
    m.utime, m.num_joints = 123, num_joints
    for name in ("joint_position_measured", "joint_velocity_estimated", "joint_position_commanded",
                 "joint_position_ipo", "joint_torque_measured", "joint_torque_commanded",
                 "joint_torque_external"):
        setattr(m, name, [0.1 * j for j in range(num_joints)])
    return m


def test_a_short_message_is_one_lc02_datagram():
    [d] = bus.encode_datagrams("AB", b"xyz", 7)
    assert d == b"LC02" + b"\0\0\0\x07" + b"AB\0" + b"xyz"


def test_a_300_kB_message_is_five_lc03_fragments_laid_out_as_lcm_does():
    payload = bytes(i % 251 for i in range(300000))
    ds = bus.encode_datagrams("IMG", payload, 9)
    # channel + NUL + payload = 300004 bytes in fragments of 65487: ceil(300004 / 65487) = 5.
    assert len(ds) == 5
    headers = [struct.unpack(">4sIIIHH", d[:20]) for d in ds]
    assert [h[0] for h in headers] == [b"LC03"] * 5
    assert {h[1] for h in headers} == {9} and {h[2] for h in headers} == {300000}
    # Fragment 0 carries "IMG\0" and 65487 - 4 = 65483 payload bytes; the others 65487 each.
    assert [h[3] for h in headers] == [0, 65483, 65483 + 65487, 65483 + 2 * 65487, 65483 + 3 * 65487]
    assert [h[4] for h in headers] == [0, 1, 2, 3, 4] and {h[5] for h in headers} == {5}
    assert ds[0][20:24] == b"IMG\0"
    assert [len(d) - 20 for d in ds] == [65487] * 4 + [300000 - 65483 - 3 * 65487 + 0]
    assert b"".join([ds[0][24:]] + [d[20:] for d in ds[1:]]) == payload


def test_the_short_limit_is_65499_bytes_of_channel_nul_and_payload():
    assert len(bus.encode_datagrams("C", b"\0" * (65499 - 2), 0)) == 1
    assert len(bus.encode_datagrams("C", b"\0" * (65499 - 1), 0)) == 2


def test_fragments_reassemble_in_any_order_and_from_two_senders_at_once():
    got = []
    r = bus.Reassembler(lambda reason: got.append(reason))
    a = bus.encode_datagrams("A", b"a" * 200000, 1)
    b = bus.encode_datagrams("B", b"b" * 140000, 1)
    out = []
    for da, db in zip(reversed(a), b + [None]):
        out.append(r.feed(da, ("10.0.0.1", 1)))
        if db is not None:
            out.append(r.feed(db, ("10.0.0.2", 1)))
    whole = [o for o in out if o is not None]
    assert whole == [("B", b"b" * 140000), ("A", b"a" * 200000)] and got == [] and not r.partials


def feed_all(b, datagrams, sender=("10.0.0.9", 5)):
    return sum(b.feed(d, sender) for d in datagrams)


def test_hostile_datagrams_are_refused_and_counted():
    b = bus.Bus(max_message_bytes=1 << 20, max_partials=2)
    seen = []
    b._subscriptions.append(bus.Subscription(".*", None, lambda c, m: seen.append(c)))
    fragment = struct.Struct(">4sIIIHH")
    hostile = [
        b"LC0",                                              # shorter than any header
        b"XXXX\0\0\0\0CH\0",                                 # bad magic
        b"LC02\0\0\0\0" + b"C" * 64 + b"\0",                 # channel of 64 bytes
        b"LC02\0\0\0\0" + b"C" * 100,                        # channel without its NUL
        fragment.pack(b"LC03", 1, 1 << 30, 0, 0, 2) + b"C\0",  # 1 GiB: refused before any buffer
        fragment.pack(b"LC03", 2, 100, 0, 3, 2) + b"x",      # fragment 3 of 2
        fragment.pack(b"LC03", 3, 100, 0, 0, 0) + b"C\0",    # zero fragments
        fragment.pack(b"LC03", 4, 100, 90, 1, 2) + b"x" * 20,  # past the message's end
        b"LC03\0\0\0\x05",                                   # LC03 cut inside its header
    ]
    assert feed_all(b, hostile) == 0
    assert dict(b.refused) == {"bus/short_datagram": 1, "bus/magic": 1, "bus/channel": 2, "bus/too_large": 1,
                               "bus/fragment_header": 3, "bus/fragment_range": 1}
    assert not b._reassembler.partials and seen == []
    # A repeated fragment is refused; three messages begun with room for two: the oldest dropped.
    starts = [bus.encode_datagrams("C", bytes(100000), seq)[0] for seq in (10, 11, 12)]
    assert feed_all(b, starts + starts[2:]) == 0
    assert b.refused["bus/partial_evicted"] == 1 and b.refused["bus/fragment_duplicate"] == 1
    assert len(b._reassembler.partials) == 2
    # The bytes that came (and a fragment's overhead), not the 100 kB claimed.
    assert b._reassembler.partial_bytes == 2 * (65487 - 2 + bus.CHUNK_OVERHEAD_BYTES)
    # A flood of first fragments each claiming 1 MiB costs their own bytes, not 1 MiB each.
    r = bus.Reassembler(lambda reason: None, max_partials=1000)
    claim = fragment.pack(b"LC03", 0, 1 << 20, 0, 0, 17) + b"C\0" + b"x" * 10
    for seq in range(1000):
        r.feed(claim[:4] + struct.pack(">I", seq) + claim[8:], ("10.0.0.1", 1))
    assert len(r.partials) == 1000 and r.partial_bytes == 1000 * (10 + bus.CHUNK_OVERHEAD_BYTES)
    # Partial messages hold at most max_partial_bytes together: a third 10 MB one drops the oldest.
    r = bus.Reassembler(lambda reason: None, max_partials=8, max_partial_bytes=25 << 20)
    for seq in range(3):
        for d in bus.encode_datagrams("C", bytes(10 << 20), seq)[:-1]:
            r.feed(d, ("10.0.0.1", 1))
    assert [k[1] for k in r.partials] == [1, 2]
    # Fragments that overlap and leave a hole are refused when the last arrives.
    ds = bus.encode_datagrams("C", bytes(200000), 50)
    head = bytearray(ds[1][:20])
    head[12:16] = struct.pack(">I", 0)  # fragment 1 claims offset 0, over fragment 0's bytes
    assert feed_all(b, [ds[0], bytes(head) + ds[1][20:]] + ds[2:]) == 0 and b.refused["bus/fragment_range"] == 2
    # The bus still delivers.
    assert feed_all(b, bus.encode_datagrams("OK", bytes(100000), 13)) == 1 and seen == ["OK"]


def test_a_message_is_walked_before_it_is_decoded():
    b = bus.Bus()
    got = []
    b._subscriptions.append(bus.Subscription("IIWA_STATUS", lcm.iiwa_status_t, lambda c, m: got.append(m)))
    good = status().encode()
    huge = bytearray(status(0).encode())
    huge[16:20] = struct.pack(">i", 2**31 - 1)  # num_joints after the fingerprint and utime
    start = time.monotonic()
    for payload in (bytes(huge), good[:12], good + b"\0", b"\1" * 8 + good[8:]):
        assert b.feed(bus.encode_datagrams("IIWA_STATUS", payload, 1)[0]) == 0
    assert time.monotonic() - start < 0.5  # 2^31 - 1 joints cost nothing
    assert dict(b.refused) == {"IIWA_STATUS/decode/count": 1, "IIWA_STATUS/decode/truncated": 1,
                               "IIWA_STATUS/decode/trailing": 1, "IIWA_STATUS/decode/fingerprint": 1}
    assert b.feed(bus.encode_datagrams("IIWA_STATUS", good, 2)[0]) == 1
    assert got[0].joint_position_measured == pytest.approx([0.1 * j for j in range(7)])


def test_strings_are_walked_as_the_cpp_reader_walks_them():
    m = lcm.process_status_t()
    m.name, m.host, m.last_error = "sim", "h", ""
    good = bytearray(m.encode())
    wire.check(lcm.process_status_t, bytes(good))
    at = 8 + 8  # the fingerprint, then utime; then name: int32 length 4, "sim\0"
    assert good[at:at + 8] == b"\0\0\0\x04sim\0"
    for edit, kind in (((at, b"\0\0\0\0"), "string"), ((at + 4, b"s\0m\0"), "string"),
                       ((at + 4, b"simX"), "string"), ((at, b"\x7f\0\0\0"), "truncated")):
        bad = bytearray(good)
        bad[edit[0]:edit[0] + len(edit[1])] = edit[1]
        with pytest.raises(wire.WireError) as e:
            wire.check(lcm.process_status_t, bytes(bad))
        assert e.value.kind == kind


def test_a_callback_that_raises_is_counted_and_the_bus_goes_on():
    b = bus.Bus()
    b._subscriptions.append(bus.Subscription("X", None, lambda c, m: 1 / 0))
    assert b.feed(bus.encode_datagrams("X", b"1", 0)[0]) == 0
    assert b.refused == {"X/handler": 1}


def test_urls():
    assert bus.parse_url("udpm://239.255.76.67:7667?ttl=0") == ("239.255.76.67", 7667, 0, None)
    assert bus.parse_url("udpm://239.1.2.3:9000?ttl=1&recv_buf_size=4096") == ("239.1.2.3", 9000, 1, 4096)
    with pytest.raises(ValueError):
        bus.parse_url("tcpq://localhost:7700")


def test_the_heartbeat_carries_the_counts_and_refusals():
    b = bus.Bus()
    b._subscriptions.append(bus.Subscription("X", lcm.iiwa_status_t, lambda c, m: None))
    b.feed(b"LC0")
    b.feed(bus.encode_datagrams("X", b"\0" * 8, 0)[0])
    b.feed(bus.encode_datagrams("X", status().encode(), 1)[0])
    m = b.status("py-test")
    assert (m.name, m.state, m.messages_in, m.messages_out) == ("py-test", m.STATE_RUNNING, 2, 0)
    assert list(zip(m.reject_reason, m.reject_count)) == [("X/decode/fingerprint", 1), ("bus/short_datagram", 1)]
    assert m.rejected_inputs == 2 and m.num_reasons == 2
    wire.check(lcm.process_status_t, m.encode())
