"""The generated Python types (orbed_lcm) against the C++ ones: every fingerprint equal to the one the
C++ headers compute (orbed-py-peer prints them), and a message encoded in Python walked by the
structure table and decoded back."""
import glob
import os
import subprocess

from orbed import types, wire

lcm = types.lcm_types()


def test_every_fingerprint_equals_the_cpp_one():
    peer = os.path.join(types.build_dir(), "tests", "orbed-py-peer")
    lines = subprocess.run([peer, "fingerprints"], check=True, capture_output=True, text=True).stdout.split()
    cpp = dict(zip(lines[0::2], lines[1::2]))
    lcm_files = glob.glob(os.path.join(os.path.dirname(__file__), "..", "..", "lcmtypes", "orbed_*.lcm"))
    assert len(cpp) == len(types.structs()) == len(lcm_files)  # one struct a file
    python = {name: getattr(lcm, name)._get_packed_fingerprint().hex() for name in types.structs()}
    assert python == cpp


def test_a_python_message_round_trips_through_the_walk():
    m = lcm.collision_status_t()
    m.num_contacts, m.num_links = 1, 2
    c = lcm.contact_t()
    c.body_a, c.body_b, c.distance_m, c.p_WA_m, c.p_WB_m = "link_7", "table, top", 0.25, [1, 2, 3], [4, 5, 6]
    m.contacts, m.link_names, m.link_clearance_m = [c], ["a", "b"], [0.5, 1.5]
    back = wire.decode(lcm.collision_status_t, m.encode())
    assert back.contacts[0].body_b == "table, top" and list(back.link_clearance_m) == [0.5, 1.5]
