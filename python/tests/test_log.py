"""orbed.log's reader on a damaged log made by hand: the same events and damaged ranges as the C++
reader's (`orbed-log check` is the oracle), and the cells' float text against C++'s std::to_chars
(values whose text was printed by a C++ program)."""
import os
import re
import struct
import subprocess

import numpy as np

from orbed import flatten, log, types


def event(number, stamp, channel, data):
    return struct.pack(">Iqqii", 0xEDA1DA01, number, stamp, len(channel), len(data)) + channel + data


def test_a_damaged_log_reads_as_the_cpp_reader_reads_it(tmp_path):
    path = tmp_path / "damaged.lcmlog"
    path.write_bytes(event(0, 1000, b"A", b"x" * 10) + b"garbage!" + event(1, 2000, b"B", b"y" * 5)
                     + struct.pack(">Iqqii", 0xEDA1DA01, 2, 3000, 300, 1) + b"z" * 40  # channel of 300 bytes
                     + event(3, 4000, b"C", b"") + event(4, 5000, b"D", b"w" * 100)[:-7])  # cut at the end
    reader = log.Reader(path.read_bytes())
    events = [(e.event_number, e.timestamp_us, e.channel, bytes(e.data), e.offset) for e in reader]
    assert events == [(0, 1000, "A", b"x" * 10, 0), (1, 2000, "B", b"y" * 5, 47), (3, 4000, "C", b"", 149)]
    check = subprocess.run([os.path.join(types.build_dir(), "bin", "orbed-log"), "check", str(path)],
                           capture_output=True, text=True)
    assert check.returncode == 1
    cpp = [(int(a), int(b) - int(a), reason) for a, b, reason in
           re.findall(r"damaged bytes (\d+)\.\.(\d+) \(\d+ bytes\): (.*)", check.stdout)]
    assert [tuple(d) for d in reader.damage] == cpp and len(cpp) == 3


def test_floats_are_written_as_cpp_to_chars_writes_them():
    # std::to_chars(double) of each value, printed by a C++17 program with libstdc++ 12 (nan and the
    # infinities: ShortestDecimal's own text, base/format.cc).
    doubles = {1.2345678901234567e20: "123456789012345667584", 0.0001: "1e-04", 1e-5: "1e-05", 123456.0: "123456",
               1e16: "1e+16", 1e15: "1e+15", -0.0: "-0", 5e-324: "5e-324", 1.7976931348623157e308:
               "1.7976931348623157e+308", 0.1: "0.1", -2.25e-7: "-2.25e-07", 100.0: "100", float("nan"): "nan",
               float("-inf"): "-inf"}
    assert {v: flatten.shortest(v) for v in doubles} == doubles
    floats = {0.1: "0.1", 1e-5: "1e-05", 3.4028235e38: "3.4028235e+38", 16777217.0 * 64: "1073741824"}
    assert {v: flatten.shortest(float(np.float32(v)), True) for v in floats} == floats
