#!/usr/bin/env bash
# replay_gui_test.sh ROOT WORKDIR: `scripts/orbed replay --gui` in a virtual X server (Xvfb), inside a
# private network namespace where LCM's own lcm-logger records what the player sends:
#   - the window opens (an X window named "LogPlayer") and is a real picture (a screenshot with more
#     than 10 colours, WORKDIR/replay_gui.png);
#   - it plays: the 300 events of a log written here (100 Hz, REPLAY_TEST, payload = the event's
#     index; then one REPLAY_END) arrive at the recorder, at least 290 of them, in order.
# Needs xvfb-run, xwininfo (x11-utils), a Java runtime with AWT (default-jre), lcm-logger and the build
# tree's lcm-spy jar ($ORBED_BUILD_DIR, default build/): `scripts/orbed setup` installs them.
set -euo pipefail
root=$1 work=$2
rm -rf "$work"
mkdir -p "$work"

# The log to play: LCM's event log format (sync word, event number, utime, channel and data sizes).
/usr/bin/python3 - "$work/in.lcmlog" <<'PY'
import struct, sys
with open(sys.argv[1], "wb") as f:
    events = [(b"REPLAY_TEST", 1_000_000 + i * 10_000, struct.pack(">i", i)) for i in range(300)]
    # lcm-logger flushes its file when an event arrives after its flush interval (0.1 s): a last
    # event 0.5 s later puts the 300 on disk.
    events.append((b"REPLAY_END", 1_000_000 + 300 * 10_000 + 500_000, b"end"))
    for i, (channel, utime, data) in enumerate(events):
        f.write(struct.pack(">IqqII", 0xEDA1DA01, i, utime, len(channel), len(data)))
        f.write(channel + data)
PY

export ROOT="$root" WORK="$work"
"$root/scripts/netns-exec" bash -c '
  set -euo pipefail
  lcm-logger -c "REPLAY_.*" "$WORK/out.lcmlog" >"$WORK/logger.txt" 2>&1 & logger=$!
  trap "kill -INT $logger 2>/dev/null; wait $logger 2>/dev/null || true" EXIT
  for _ in $(seq 1 200); do [[ -f "$WORK/out.lcmlog" ]] && break; sleep 0.05; done
  [[ -f "$WORK/out.lcmlog" ]] || { echo "lcm-logger did not start"; exit 1; }
  xvfb-run -a -s "-screen 0 1024x640x24" bash -c "
    \"\$ROOT/scripts/orbed\" replay --gui \"\$WORK/in.lcmlog\" >\"\$WORK/player.txt\" 2>&1 & player=\$!
    # Until the recorder holds the whole log (3 s of events) or 60 s pass.
    for _ in \$(seq 1 600); do
      [[ \$(stat -c %s \"\$WORK/out.lcmlog\") -ge \$((300 * 43)) ]] && break
      sleep 0.1
    done
    xwininfo -root -tree > \"\$WORK/windows.txt\"
    java \"\$ROOT/tests/tools/Screenshot.java\" \"\$WORK/replay_gui.png\" > \"\$WORK/screenshot.txt\"
    pkill -f \"lcm[.]logging[.]LogPlayer\" 2>/dev/null || true
    wait \$player 2>/dev/null || true
  "
'

grep -q '"LogPlayer"' "$work/windows.txt" || { echo "no LogPlayer window"; cat "$work/player.txt"; exit 1; }
read -r size colours < "$work/screenshot.txt"
[[ $colours -gt 10 ]] || { echo "the screenshot ($size) has $colours colours: blank"; exit 1; }
/usr/bin/python3 - "$work/out.lcmlog" "$work/replay_gui.png" <<'PY'
import struct, sys
data = open(sys.argv[1], "rb").read()
pos, seen = 0, []
while pos + 28 <= len(data):
    sync, _, _, clen, dlen = struct.unpack(">IqqII", data[pos:pos + 28])
    assert sync == 0xEDA1DA01, f"bad sync word at byte {pos}"
    channel = data[pos + 28:pos + 28 + clen].decode()
    payload = data[pos + 28 + clen:pos + 28 + clen + dlen]
    if channel == "REPLAY_TEST":
        seen.append(struct.unpack(">i", payload)[0])
    pos += 28 + clen + dlen
assert len(seen) >= 290, f"the recorder got {len(seen)} of the 300 events played"
assert seen == sorted(seen), "events out of order"
print(f"replay --gui: window open (screenshot {sys.argv[2]}), {len(seen)} of 300 events played in order")
PY
