// orbed-log export --mcap's writer: reads records framed by orbed-log (procs/logger/mcap_export.cc)
// on stdin and writes them with @mcap/core's McapWriter into OUT (first OUT.part, renamed when whole):
// chunked, with message indexes, chunk indexes, statistics, the metadata index and summary offsets,
// so readers (Foxglove) seek by the index. Chunks are not compressed.
//
// usage: node mcap_writer.mjs OUT
//
// A frame: kind (1 byte: S schema, C channel, M message, D metadata, E end) | header length (uint32
// LE) | header (JSON) | body length (uint32 LE) | body. Headers: S {id, name, encoding}, body the
// schema; C {id, schemaId, topic, messageEncoding, metadata}; M {channelId, sequence, logTime,
// publishTime} (times in ns as decimal strings), body the message; D {name, metadata}; E {}.
// The ids are orbed-log's; the writer's own are mapped. Input that ends without E, or a frame that
// is not one of these, leaves no file and exit code 1.
import { McapWriter } from "@mcap/core";
import { closeSync, openSync, readFileSync, readSync, renameSync, rmSync, writeSync } from "node:fs";

const out = process.argv[2];
if (!out) {
  process.stderr.write("usage: node mcap_writer.mjs OUT\n");
  process.exit(2);
}
const version = JSON.parse(
  readFileSync(new URL("./node_modules/@mcap/core/package.json", import.meta.url), "utf8")).version;

// Blocking reads of stdin (a pipe from orbed-log), through one growing buffer.
let buffer = Buffer.alloc(1 << 20), start = 0, end = 0, eof = false;
function fill(need) {
  while (end - start < need && !eof) {
    if (start > 0) {
      buffer.copy(buffer, 0, start, end);
      end -= start;
      start = 0;
    }
    if (buffer.length < need) {
      const bigger = Buffer.alloc(Math.max(need, 2 * buffer.length));
      buffer.copy(bigger, 0, 0, end);
      buffer = bigger;
    }
    let n;
    try {
      n = readSync(0, buffer, end, buffer.length - end, null);
    } catch (e) {
      if (e.code === "EAGAIN") continue;
      if (e.code === "EOF") n = 0; else throw e;
    }
    if (n === 0) eof = true;
    end += n;
  }
  return end - start >= need;
}
function take(n) {
  if (!fill(n)) throw new Error("the input ended inside a frame");
  const bytes = buffer.subarray(start, start + n);
  start += n;
  return bytes;
}
function nextFrame() {
  if (!fill(1)) return null;
  const kind = String.fromCharCode(take(1)[0]);
  const header = JSON.parse(take(take(4).readUInt32LE(0)).toString("utf8"));
  const body = Uint8Array.from(take(take(4).readUInt32LE(0)));
  return { kind, header, body };
}

const part = `${out}.part`;
const fd = openSync(part, "w");
let position = 0n;
const writable = {
  async write(bytes) {
    for (let done = 0; done < bytes.length;) done += writeSync(fd, bytes, done, bytes.length - done);
    position += BigInt(bytes.length);
  },
  position: () => position,
};
const writer = new McapWriter({
  writable, useStatistics: true, useSummaryOffsets: true, useChunks: true, useChunkIndex: true,
  useMessageIndex: true, useMetadataIndex: true, useAttachmentIndex: true, chunkSize: 4 << 20,
});

try {
  await writer.start({ profile: "", library: `orbed-log export --mcap, @mcap/core ${version}` });
  const schemaIds = new Map(), channelIds = new Map();
  let whole = false;
  for (let f = nextFrame(); f && !whole; f = nextFrame()) {
    const h = f.header;
    if (f.kind === "S") {
      schemaIds.set(h.id, await writer.registerSchema({ name: h.name, encoding: h.encoding, data: f.body }));
    } else if (f.kind === "C") {
      if (!schemaIds.has(h.schemaId)) throw new Error(`channel ${h.topic}: no schema ${h.schemaId}`);
      channelIds.set(h.id, await writer.registerChannel({
        topic: h.topic, schemaId: schemaIds.get(h.schemaId), messageEncoding: h.messageEncoding,
        metadata: new Map(Object.entries(h.metadata)),
      }));
    } else if (f.kind === "M") {
      if (!channelIds.has(h.channelId)) throw new Error(`a message on no channel (${h.channelId})`);
      await writer.addMessage({
        channelId: channelIds.get(h.channelId), sequence: h.sequence, logTime: BigInt(h.logTime),
        publishTime: BigInt(h.publishTime), data: f.body,
      });
    } else if (f.kind === "D") {
      await writer.addMetadata({ name: h.name, metadata: new Map(Object.entries(h.metadata)) });
    } else if (f.kind === "E") {
      whole = true;
    } else {
      throw new Error(`a frame of kind ${JSON.stringify(f.kind)}`);
    }
  }
  if (!whole) throw new Error("the input ended before its end frame (orbed-log stopped)");
  await writer.end();
} catch (e) {
  rmSync(part, { force: true });
  process.stderr.write(`mcap_writer: ${e.message}\n`);
  process.exit(1);
} finally {
  closeSync(fd);
}
renameSync(part, out);
