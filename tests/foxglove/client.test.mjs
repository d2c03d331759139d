// orbed-foxglove-bridge seen by a client built on Foxglove's own protocol library
// (@foxglove/ws-protocol's FoxgloveClient over the `ws` WebSocket), run with node's test runner by
// tests/integration/foxglove_integration_test.cc, which starts the bridge beside the sim, publishes a
// JPEG on HMD_CAMERA and writes what the bus said into $ORBED_EXPECT_JSON:
//   { "X_WR": {"translation": [x, y, z], "rotation": [x, y, z, w]},
//     "X_R_ee": {...},                      // forward kinematics of ROBOT_STATE's joints
//     "jpeg_path": "<the JPEG file it publishes>", "scene_object": "<name of an object of the scene>",
//     "X_WD": {...}, "fixed_view_jpeg_path": "..." }  // optional: FIXED_VIEW's camera pose and picture
// The test subscribes to /tf, /scene and /hmd/camera (and /fixed_view when expected) and checks the
// frames against those values, the image bytes exactly, and the scene's entities.
import { test } from "node:test";
import assert from "node:assert/strict";
import { readFileSync } from "node:fs";
import WebSocket from "ws";
import wsProtocol from "@foxglove/ws-protocol";  // a CommonJS package: its exports on the default

const { FoxgloveClient } = wsProtocol;

const expected = JSON.parse(readFileSync(process.env.ORBED_EXPECT_JSON, "utf8"));
const url = process.env.ORBED_FOXGLOVE_URL;
const topics = ["/tf", "/scene", "/hmd/camera"].concat(expected.fixed_view_jpeg_path ? ["/fixed_view"] : []);

function assertPose(transform, pose, what) {
  const t = transform.translation, r = transform.rotation;
  const got = [t.x, t.y, t.z], q = [r.x, r.y, r.z, r.w];
  for (let i = 0; i < 3; ++i) assert.ok(Math.abs(got[i] - pose.translation[i]) < 1e-9, `${what} translation ${got}`);
  // q and -q are one rotation.
  const sign = q.reduce((s, v, i) => s + v * pose.rotation[i], 0) < 0 ? -1 : 1;
  for (let i = 0; i < 4; ++i) assert.ok(Math.abs(sign * q[i] - pose.rotation[i]) < 1e-9, `${what} rotation ${q}`);
}

test("the testbed over foxglove.websocket.v1", async () => {
  const client = new FoxgloveClient({ ws: new WebSocket(url, [FoxgloveClient.SUPPORTED_SUBPROTOCOL]) });
  const decoder = new TextDecoder();
  const latest = new Map();  // topic -> last payload
  let serverInfo = null;
  await new Promise((resolve, reject) => {
    const timer = setTimeout(() => reject(new Error(`timed out; seen ${[...latest.keys()]}`)), 60000);
    const topicOf = new Map();  // subscription id -> topic
    client.on("serverInfo", (info) => { serverInfo = info; });
    client.on("advertise", (channels) => {
      for (const c of channels) {
        if (topics.includes(c.topic)) topicOf.set(client.subscribe(c.id), c.topic);
      }
    });
    client.on("message", ({ subscriptionId, data }) => {
      latest.set(topicOf.get(subscriptionId), JSON.parse(decoder.decode(data)));
      if (latest.size === topics.length) {
        clearTimeout(timer);
        resolve();
      }
    });
    client.on("error", (e) => { clearTimeout(timer); reject(e); });
  });
  client.close();

  assert.equal(serverInfo.name, "orbed-foxglove-bridge");
  const tf = latest.get("/tf").transforms;
  const frame = (parent, child) => {
    const f = tf.find((t) => t.parent_frame_id === parent && t.child_frame_id === child);
    assert.ok(f, `no ${parent} -> ${child} in /tf`);
    return f;
  };
  assertPose(frame("W", "R"), expected.X_WR, "X_WR");
  assertPose(frame("R", "iiwa_link_ee"), expected.X_R_ee, "X_R_ee");

  const image = latest.get("/hmd/camera");
  assert.equal(image.format, "jpeg");
  assert.equal(image.frame_id, "C");
  assert.equal(image.data, readFileSync(expected.jpeg_path).toString("base64"));

  if (expected.fixed_view_jpeg_path) {
    assertPose(frame("W", "D"), expected.X_WD, "X_WD");
    const picture = latest.get("/fixed_view");
    assert.equal(picture.format, "jpeg");
    assert.equal(picture.frame_id, "D");
    assert.equal(picture.data, readFileSync(expected.fixed_view_jpeg_path).toString("base64"));
  }

  const entities = latest.get("/scene").entities;
  assert.ok(entities.some((e) => e.id === "robot/iiwa_link_1" && e.frame_id === "iiwa_link_1" && e.frame_locked));
  assert.ok(entities.some((e) => e.id === `scene/${expected.scene_object}` && e.frame_id === "W"));
});
