"""The bounded walk: checks that bytes are exactly one encoded message of a type before the generated
decode reads them, with every array count checked against the bytes left, so hostile bytes cost
O(their length) and nothing is allocated from a count. The same rules and reasons as the C++
DecodeBounded (lcmtypes/wire_reader.h, bounded_decode.h); the structure comes from the .lcm files at
build time (orbed_lcm._structure). Pure; thread-safe.

Reasons (WireError.kind): truncated, fingerprint, count, string, trailing, decode.
"""
import struct

from orbed import types

PRIMITIVE_BYTES = {"int8_t": 1, "byte": 1, "boolean": 1, "int16_t": 2, "int32_t": 4, "int64_t": 8,
                   "float": 4, "double": 8}
_SIGNED = {1: ">b", 2: ">h", 4: ">i", 8: ">q"}


class WireError(Exception):
    """Bytes that are not one well-formed message: kind is the counted reason, str() says where."""

    def __init__(self, kind, field, what, position, size):
        super().__init__(f"{field}: {what} at byte {position} of {size}")
        self.kind = kind


class _Reader:
    def __init__(self, data):
        self.data = memoryview(data)
        self.pos = 0

    def remaining(self):
        return len(self.data) - self.pos

    def fail(self, kind, field, what):
        raise WireError(kind, field, what, self.pos, len(self.data))

    def skip(self, n, field):
        if n > self.remaining():
            self.fail("truncated", field, f"needs {n} bytes")
        self.pos += n

    def integer(self, n, field):
        if n > self.remaining():
            self.fail("truncated", field, f"needs {n} bytes")
        value = struct.unpack_from(_SIGNED[n], self.data, self.pos)[0]
        self.pos += n
        return value

    def string(self, field):
        length = self.integer(4, field)
        if length < 1:
            self.fail("string", field, f"string length {length} < 1")
        if length > self.remaining():
            self.fail("truncated", field, f"string of {length} bytes")
        body = self.data[self.pos:self.pos + length]
        first_nul = bytes(body).find(b"\0")
        if first_nul != length - 1:
            self.fail("string", field, "string without its terminating NUL" if first_nul < 0
                      else "string with an embedded NUL")
        self.pos += length

    def count(self, dims, field):
        n = 1
        for dim in dims:
            if dim < 0:
                self.fail("count", field, f"negative dimension {dim}")
            if dim > 0 and n > self.remaining() // dim:
                self.fail("count", field, f"dimension {dim} cannot fit in {self.remaining()} bytes")
            n *= dim
        return n


def _walk(structs, name, r):
    sizes = {}
    for type_name, field, dims, _ in structs[name]:
        label = f"{name}.{field}"
        if dims:
            n = r.count([int(d) if d.isdigit() else sizes[d] for d in dims], label)
            if type_name in PRIMITIVE_BYTES:
                element = PRIMITIVE_BYTES[type_name]
                if n > r.remaining() // element:
                    r.fail("count", label, f"{n} elements of {element} bytes cannot fit in {r.remaining()} bytes")
                r.pos += n * element
            else:
                for _ in range(n):
                    _element(structs, type_name, label, r)
        elif type_name in PRIMITIVE_BYTES and type_name not in ("float", "double", "boolean"):
            sizes[field] = r.integer(PRIMITIVE_BYTES[type_name], label)
        else:
            _element(structs, type_name, label, r)


def _element(structs, type_name, label, r):
    if type_name in PRIMITIVE_BYTES:
        r.skip(PRIMITIVE_BYTES[type_name], label)
    elif type_name == "string":
        r.string(label)
    else:
        _walk(structs, type_name, r)


def check(message_type, data):
    """Raises WireError unless `data` is exactly one encoded `message_type` (fingerprint first)."""
    name = message_type.__name__
    r = _Reader(data)
    if r.remaining() < 8:
        r.fail("truncated", "fingerprint", "needs 8 bytes")
    if bytes(r.data[:8]) != message_type._get_packed_fingerprint():
        r.fail("fingerprint", name, "not this type's fingerprint")
    r.pos = 8
    _walk(types.structs(), name, r)
    if r.remaining() > 0:
        r.fail("trailing", name, f"{r.remaining()} bytes left over")


def decode(message_type, data):
    """The message `data` encodes, if and only if it is exactly one well-formed `message_type`."""
    check(message_type, data)
    try:
        return message_type.decode(bytes(data))
    except Exception as e:  # the walk passed: a disagreement is a generator bug, counted as such
        raise WireError("decode", message_type.__name__, f"the generated decode failed ({e})", 0, len(data))
