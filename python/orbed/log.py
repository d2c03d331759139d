"""orbed.log: LCM event logs (.lcmlog, as orbed-logger and lcm-logger write them) in Python.

    for event in orbed.log.events("logs/<run>/orbed-<time>.lcmlog"): ...   # Event tuples
    frames = orbed.log.tables(path)            # {channel: DataFrame}, as `orbed-log export --csv`
    frames = orbed.log.tables(path, text=True)  # the same cells as the CSV's text

Format, per event, big-endian: uint32 sync 0xEDA1DA01 | int64 event number | int64 timestamp [us
since the Unix epoch] | int32 channel length | int32 data length | channel | data. Damage is skipped
as the C++ reader (procs/logger/event_log_reader.h) skips it: a header that is not an event (no sync
word, a channel length outside 1..256, a negative data length, an event cut short) is skipped up to
the next sync word, and the skipped byte ranges are kept (Reader.damage). Lengths are checked
against the bytes that are there before anything is sliced.

tables() follows the C++ export (procs/logger/csv_export.h) rule for rule: a channel's type is the
one its messages' fingerprints name with the most decoded messages (the first seen on a tie); a
message is decoded only after the bounded walk (orbed.wire) and one that fails is no row, counted
under its reason; columns are named and written as orbed.flatten says, in the order the C++ export
merges them (an array's longer messages put their extra elements after the shorter ones' last);
the first column is "log_utime (us)". Typed frames hold numbers (int or float, booleans as 1/0, a
byte array as its length) and strings, NaN where a message has no such cell; text frames hold the
cells' text as a CSV reader gives it back, "" where the CSV cell is empty; csv_text(frame) is the
file `orbed-log export --csv` writes, byte for byte. Single-threaded.
"""
import collections
import mmap
import re
import struct

import pandas as pd

from orbed import flatten, types, wire

SYNC = 0xEDA1DA01
SYNC_BYTES = struct.pack(">I", SYNC)
HEADER = struct.Struct(">Iqqii")  # sync, event number, timestamp, channel length, data length
MAX_CHANNEL_BYTES = 256

Event = collections.namedtuple("Event", "event_number timestamp_us channel data offset")
Damage = collections.namedtuple("Damage", "offset bytes reason")


class Reader:
    """Walks the events of a log held in `data` (bytes, mmap or memoryview); see the module doc."""

    def __init__(self, data):
        self.data = data
        self.damage = []

    def _problem(self, pos):
        left = len(self.data) - pos
        if left < HEADER.size:
            return f"header cut short ({left} bytes left)"
        sync, _, _, channel_bytes, data_bytes = HEADER.unpack_from(self.data, pos)
        if sync != SYNC:
            return "no sync word"
        if channel_bytes < 1 or channel_bytes > MAX_CHANNEL_BYTES:
            return f"channel length {channel_bytes}"
        if data_bytes < 0:
            return f"data length {data_bytes}"
        if channel_bytes + data_bytes > left - HEADER.size:
            return f"event of {channel_bytes + data_bytes} bytes cut short ({left} bytes left)"
        return ""

    def _record(self, start, end, reason):
        if self.damage and self.damage[-1].offset + self.damage[-1].bytes == start:
            last = self.damage[-1]
            self.damage[-1] = Damage(last.offset, last.bytes + end - start, last.reason)
        else:
            self.damage.append(Damage(start, end - start, reason))

    def __iter__(self):
        pos, size = 0, len(self.data)
        view = memoryview(self.data)
        while pos < size:
            problem = self._problem(pos)
            if problem:
                found = self.data.find(SYNC_BYTES, pos + 1)
                end = size if found < 0 else found
                self._record(pos, end, problem)
                pos = end
                continue
            _, number, stamp, channel_bytes, data_bytes = HEADER.unpack_from(self.data, pos)
            start = pos + HEADER.size
            channel = bytes(view[start:start + channel_bytes]).decode("utf-8", "replace")
            body = view[start + channel_bytes:start + channel_bytes + data_bytes]
            yield Event(number, stamp, channel, body, pos)
            pos = start + channel_bytes + data_bytes


def _mapped(path):
    with open(path, "rb") as f:
        if f.seek(0, 2) == 0:
            return b""
        return mmap.mmap(f.fileno(), 0, access=mmap.ACCESS_READ)


def events(path):
    """The log's events in file order (damage skipped); Event.data is a memoryview into the file."""
    yield from Reader(_mapped(path))


class _TypeColumns:
    def __init__(self, first_seen):
        self.first_seen = first_seen
        self.columns = []
        self.column_of = {}
        self.rows = []  # (log_utime, [(name, text, value)])
        self.refused = collections.Counter()

    def merge(self, names):
        """Adds the names not yet known, each right after the known name before it in `names`."""
        insert_at = 0
        for name in names:
            if name in self.column_of:
                insert_at = self.column_of[name] + 1
                continue
            self.columns.insert(insert_at, name)
            for k in range(insert_at, len(self.columns)):
                self.column_of[self.columns[k]] = k
            insert_at += 1


class Export:
    """What tables() found: per channel its frame, type name, refusals; unknown-fingerprint counts;
    the log's damage."""

    def __init__(self):
        self.frames, self.types, self.refused, self.unknown, self.damage = {}, {}, {}, {}, []


def export(path, text=False, channels=None):
    """The log as `orbed-log export --csv` sees it (module doc); channels: a regular expression the
    whole channel name must match."""
    pattern = re.compile(channels) if channels else None
    by_fingerprint = types.type_by_fingerprint()
    seen = {}  # channel -> {type: _TypeColumns}
    unknown = collections.Counter()
    reader = Reader(_mapped(path))
    for event in reader:
        if pattern is not None and not pattern.fullmatch(event.channel):
            continue
        per_type = seen.setdefault(event.channel, {})
        message_type = by_fingerprint.get(bytes(event.data[:8])) if len(event.data) >= 8 else None
        if message_type is None:
            unknown[event.channel] += 1
            continue
        t = per_type.get(message_type)
        if t is None:
            t = per_type[message_type] = _TypeColumns(len(per_type) + 1)
        try:
            message = wire.decode(message_type, event.data)
        except wire.WireError as e:
            t.refused[e.kind] += 1
            continue
        cells = flatten.flatten(message)
        t.merge([name for name, _, _ in cells])
        t.rows.append((event.timestamp_us, cells))
    out = Export()
    out.damage = reader.damage
    out.unknown = dict(unknown)
    for channel in sorted(seen):
        per_type = seen[channel]
        if not per_type:
            continue
        chosen = min(per_type, key=lambda k: (-len(per_type[k].rows), per_type[k].first_seen))
        t = per_type[chosen]
        refused = collections.Counter(t.refused)
        for other, o in per_type.items():
            if other is not chosen:
                refused[f"another type ({other.__name__})"] += len(o.rows) + sum(o.refused.values())
        out.types[channel] = chosen.__name__
        out.refused[channel] = dict(refused)
        out.frames[channel] = _frame(t, text)
    return out


def _frame(t, text):
    columns = ["log_utime (us)"] + t.columns
    empty = "" if text else float("nan")
    rows = []
    for stamp, cells in t.rows:
        row = [empty] * len(columns)
        row[0] = str(stamp) if text else stamp
        for name, cell, value in cells:
            row[t.column_of[name] + 1] = cell if text else (int(value) if isinstance(value, bool) else value)
        rows.append(row)
    return pd.DataFrame(rows, columns=columns, dtype=str if text else None)


def tables(path, text=False, channels=None):
    """{channel: DataFrame} of the log (module doc)."""
    return export(path, text, channels).frames


def csv_text(frame):
    """A text frame as the CSV file `orbed-log export --csv` writes (header row, '\\n' line ends)."""
    lines = [",".join(flatten.csv_cell(c) for c in frame.columns)]
    lines += [",".join(flatten.csv_cell(c) for c in row) for row in frame.itertuples(index=False)]
    return "".join(line + "\n" for line in lines)


def csv_file_stem(channel):
    """The file name stem `orbed-log export --csv` gives a channel ([A-Za-z0-9_.-] kept, '_' else)."""
    stem = "".join(chr(b) if chr(b).isascii() and (chr(b).isalnum() or chr(b) in "_-.") else "_"
                   for b in channel.encode())
    return "_" + stem if not stem.strip(".") else stem
