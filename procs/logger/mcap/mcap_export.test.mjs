// orbed-log export --mcap read back by independent readers, run by procs/logger/mcap_export_test.cc
// (a log made by hand) and tests/integration/mcap_integration_test.cc (a real run's log) with node
// --test on the file they exported ($ORBED_MCAP_FILE) and what the log held ($ORBED_EXPECT_JSON;
// each check below runs when its expectation is there):
//   - @mcap/core's McapIndexedReader opens it through its summary: a header, chunk indexes, the
//     statistics, the metadata index; it reads every message through the indexes, with the chunks'
//     CRCs checked; McapStreamReader reads it again front to back (every record, the chunks opened,
//     the footer included);
//   - per channel the message count equals what the log held (and the statistics say the same);
//     log times are the log's event timestamps [ns];
//   - values come back exactly: IIWA_STATUS's joint positions, HMD_POSE's X_WH, the robot base on
//     /tf, the registration's X_WV on /registration, a JPEG's bytes through /hmd/camera's base64;
//     an int64 of 2^53 + 1 as its exact decimal; NaN and +inf as null where they were;
//   - every schema compiles in ajv (JSON Schema draft-07, strict) and is in the form Foxglove's JSON
//     Schema reader takes (an object's "properties" an object, one "type" per property, no arrays of
//     arrays); every message validates against its schema, but for the nulls above; the Foxglove
//     channels' messages validate against @foxglove/schemas' own JSON schemas too;
//   - the provenance record is the metadata "provenance", and /scene draws the scene its arguments
//     name.
import { test } from "node:test";
import assert from "node:assert/strict";
import { open, readFile } from "node:fs/promises";
import { readFileSync } from "node:fs";
import { McapIndexedReader, McapStreamReader } from "@mcap/core";
import Ajv from "ajv";
import { createRequire } from "node:module";

const foxgloveSchemas = createRequire(import.meta.url)("@foxglove/schemas/jsonschema");  // CommonJS

const expected = JSON.parse(readFileSync(process.env.ORBED_EXPECT_JSON, "utf8"));
const path = process.env.ORBED_MCAP_FILE;
const decoder = new TextDecoder();
let messagesRead = -1, metadataIndexed = -1;  // by the indexed reader, for the stream reader's counts

async function openIndexed() {
  const handle = await open(path, "r");
  const { size } = await handle.stat();
  const readable = {
    size: async () => BigInt(size),
    read: async (offset, length) => {
      const bytes = new Uint8Array(Number(length));
      await handle.read(bytes, 0, bytes.length, Number(offset));
      return bytes;
    },
  };
  return { reader: await McapIndexedReader.Initialize({ readable }), handle };
}

// What Foxglove's JSON Schema reader needs, recursively (it throws on anything else).
function assertFoxgloveReadable(schema, where) {
  assert.equal(typeof schema.type, "string", `${where}: one "type"`);
  if (schema.type === "array") {
    assert.notEqual(schema.items.type, "array", `${where}: an array of arrays`);
    return assertFoxgloveReadable(schema.items, `${where}[]`);
  }
  if (schema.type !== "object") return;
  assert.ok(schema.properties && typeof schema.properties === "object" && !Array.isArray(schema.properties),
    `${where}: "properties" is not an object`);
  for (const [name, property] of Object.entries(schema.properties)) assertFoxgloveReadable(property, `${where}.${name}`);
}

function pointer(value, path) {
  return path.split("/").slice(1).reduce((v, key) => v[key], value);
}

test("the exported MCAP file, read back by @mcap/core", async () => {
  const { reader, handle } = await openIndexed();
  try {
    assert.ok(reader.chunkIndexes.length >= 1, "chunk indexes");
    assert.ok(reader.statistics, "statistics");
    assert.equal(reader.header.profile, "");
    assert.ok(reader.metadataIndexes.some((m) => m.name === "orbed.export"), "metadata index");
    metadataIndexed = reader.metadataIndexes.length;

    const ajv = new Ajv({ strict: true, allErrors: true });
    const validators = new Map();  // channel id -> validate
    const topicOf = new Map();
    for (const [id, channel] of reader.channelsById) {
      const schema = reader.schemasById.get(channel.schemaId);
      assert.equal(schema.encoding, "jsonschema");
      assert.equal(channel.messageEncoding, "json");
      const parsed = JSON.parse(decoder.decode(schema.data));
      assert.ok(ajv.validateSchema(parsed), `${schema.name}: ${ajv.errorsText()}`);
      assertFoxgloveReadable(parsed, schema.name);
      validators.set(id, { own: ajv.compile(parsed), schemaName: schema.name });
      topicOf.set(id, channel.topic);
    }
    const foxglove = new Ajv({ strict: false, allErrors: true });
    const official = {
      "foxglove.FrameTransforms": foxglove.compile(foxgloveSchemas.FrameTransforms),
      "foxglove.SceneUpdate": foxglove.compile(foxgloveSchemas.SceneUpdate),
      "foxglove.CompressedImage": foxglove.compile(foxgloveSchemas.CompressedImage),
    };

    const counts = {}, bySequence = {}, firstLogTime = {};
    const keep = (topic, sequence) => sequence < 2 || topic === "IIWA_STATUS" && sequence < 8;
    for await (const message of reader.readMessages({ validateCrcs: true })) {
      const topic = topicOf.get(message.channelId);
      const text = decoder.decode(message.data);
      const value = JSON.parse(text);
      counts[topic] = (counts[topic] ?? 0) + 1;
      if (keep(topic, message.sequence)) (bySequence[topic] ??= new Map()).set(message.sequence, { value, text });
      if (!(topic in firstLogTime)) firstLogTime[topic] = message.logTime;
      assert.equal(message.publishTime, message.logTime);
      const { own, schemaName } = validators.get(message.channelId);
      if (!own(value)) {
        // The one stated exception: a non-finite double is null where the schema says number (where
        // the log had one, when the expectation lists them).
        const nulls = (expected.nulls ?? []).filter((n) => n.topic === topic && n.sequence === message.sequence);
        assert.ok(!expected.nulls || nulls.length > 0, `${topic} #${message.sequence}: ${JSON.stringify(own.errors)}`);
        for (const error of own.errors) {
          assert.equal(error.keyword, "type", `${topic}: ${JSON.stringify(error)}`);
          assert.ok(!expected.nulls || nulls.some((n) => n.path === error.instancePath), `${topic}: ${JSON.stringify(error)}`);
          assert.equal(pointer(value, error.instancePath), null);
        }
      }
      if (official[schemaName]) {
        assert.ok(official[schemaName](value), `${topic} against @foxglove/schemas: ${JSON.stringify(official[schemaName].errors)}`);
      }
    }
    for (const [topic, n] of Object.entries(expected.counts)) assert.equal(counts[topic], n, topic);
    for (const [topic, n] of Object.entries(expected.min_counts ?? {})) assert.ok(counts[topic] >= n, `${topic}: ${counts[topic]}`);
    const listed = Object.keys(expected.counts).concat(Object.keys(expected.min_counts ?? {}));
    assert.deepEqual(Object.keys(counts).sort(), listed.sort(), "the topics");
    messagesRead = Object.values(counts).reduce((a, b) => a + b, 0);
    for (const [id, n] of reader.statistics.channelMessageCounts) assert.equal(Number(n), counts[topicOf.get(id)]);
    assert.equal(Number(reader.statistics.messageCount), Object.values(counts).reduce((a, b) => a + b, 0));
    for (const [topic, ns] of Object.entries(expected.log_times_ns ?? {})) assert.equal(firstLogTime[topic], BigInt(ns));

    // Values, exactly.
    const iiwa = bySequence["IIWA_STATUS"];
    expected.iiwa_positions.forEach((q, k) => {
      assert.deepEqual(iiwa.get(k).value.joint_position_measured, q);
      assert.ok(Object.is(iiwa.get(k).value.joint_position_measured[6], q[6]), "-0 stays -0");
    });
    assert.deepEqual(bySequence["HMD_POSE"].get(0).value.X_WH, expected.X_WH);
    const tf = bySequence["/tf"].get(0).value.transforms;
    const base = tf.find((t) => t.parent_frame_id === "W" && t.child_frame_id === "R");
    assert.deepEqual([base.translation.x, base.translation.y, base.translation.z], expected.X_WR.position_m);
    if (expected.X_WH_on_second_tf) {
      assert.equal(tf.find((t) => t.child_frame_id === "H"), undefined, "no headset before its first HMD_POSE");
      const head = bySequence["/tf"].get(1).value.transforms.find((t) => t.child_frame_id === "H");
      assert.deepEqual([head.translation.x, head.translation.y, head.translation.z], expected.X_WH.position_m);
    }
    const [w, x, y, z] = expected.X_WR.quaternion_wxyz, r = base.rotation;
    for (const [got, want] of [[r.w, w], [r.x, x], [r.y, y], [r.z, z]]) assert.ok(Math.abs(got - want) < 1e-15);
    if (expected.X_WV) {
      const virtualBase = bySequence["/tf"].get(1).value.transforms.find((t) => t.child_frame_id === "V");
      assert.deepEqual([virtualBase.translation.x, virtualBase.translation.y, virtualBase.translation.z],
        expected.X_WV.position_m);
      const registration = bySequence["/registration"].get(0).value.X_WV_mean.position;
      assert.deepEqual([registration.x, registration.y, registration.z], expected.X_WV.position_m);
      assert.ok(bySequence["/scene"].get(1).value.entities.some((e) => e.id.startsWith("virtual_robot/")));
    }
    if (expected.scene_object) {  // the run's own scene (its provenance record's), not the shipped OR
      const entities = bySequence["/scene"].get(0).value.entities;
      assert.ok(entities.some((e) => e.id === `scene/${expected.scene_object}`), "the run's scene on /scene");
      assert.ok(!entities.some((e) => e.id === "scene/floor"), "not the shipped OR's");
    }
    const jpeg = await readFile(expected.jpeg_path);
    const image = bySequence["/hmd/camera"].get(0).value;
    assert.equal(image.format, "jpeg");
    assert.deepEqual(Buffer.from(image.data, "base64"), jpeg);
    assert.deepEqual(Buffer.from(bySequence["HMD_CAMERA"].get(0).value.data, "base64"), jpeg);
    if (expected.registration_request_id) {
      assert.match(bySequence["REGISTRATION"].get(0).text, new RegExp(`"request_id":${expected.registration_request_id}\\b`));
      assert.equal(bySequence["REGISTRATION"].get(0).value.session_id, "s\uFFFD1");
    }

    // The provenance record.
    if (expected.provenance) {
      const metadata = [];
      for await (const m of reader.readMetadata({ name: "provenance" })) metadata.push(m);
      assert.equal(metadata.length, 1);
      for (const [key, value] of Object.entries(expected.provenance)) {
        assert.equal(metadata[0].metadata.get(key), typeof value === "string" ? value : JSON.stringify(value));
      }
    }
  } finally {
    await handle.close();
  }
});

test("the same file front to back with McapStreamReader", async () => {
  const stream = new McapStreamReader({ validateCrcs: true });
  stream.append(await readFile(path));
  const kinds = {};
  for (let record; (record = stream.nextRecord());) kinds[record.type] = (kinds[record.type] ?? 0) + 1;
  assert.ok(stream.done(), "the reader reached the footer and magic");
  assert.equal(kinds.Footer, 1);
  // (the reader opens the chunks and yields what is inside them)
  assert.ok(kinds.MessageIndex >= 1 && kinds.ChunkIndex >= 1 && kinds.SummaryOffset >= 1, JSON.stringify(kinds));
  assert.equal(kinds.Statistics, 1);
  assert.equal(kinds.MetadataIndex, metadataIndexed);
  assert.equal(kinds.Message, messagesRead);
});
