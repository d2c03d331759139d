// orbed-foxglove-bridge's protocol pieces and server:
//   - advertise: the seven channels with their Foxglove schema names and JSON schemas in the form
//     Foxglove's reader takes (every object with "properties" an object, every property one "type"
//     string; a "properties": null made Foxglove drop /scene); ajv validates them in the MCAP test;
//   - /tf: the flange frame 1.266 m above R at q = 0 (KUKA data sheet), R in W, the virtual links;
//   - Message Data: opcode 1, little-endian subscription id and nanoseconds, then the payload;
//   - CompressedImage: base64 by RFC 4648's test vectors ("foobar" → "Zm9vYmFy");
//   - client messages: subscribe / unsubscribe read; malformed, deep, oversized ones refused;
//   - the server on 127.0.0.1 with websocketpp's client: the subprotocol is required, serverInfo and
//     advertise come first, a subscription gets Message Data frames and an unsubscription stops them.
#include "procs/foxglove_bridge/foxglove_bridge.h"
#include "procs/foxglove_bridge/foxglove_server.h"

#include <chrono>
#include <functional>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <websocketpp/client.hpp>
#include <websocketpp/config/asio_no_tls_client.hpp>

#include "base/source_paths.h"

namespace orbed::foxglove {
namespace {

using json = nlohmann::json;

// What Foxglove's JSON Schema reader needs of an object schema, recursively.
void ExpectFoxgloveReadable(const json& schema, const std::string& path) {
  ASSERT_TRUE(schema.is_object()) << path;
  ASSERT_TRUE(schema.contains("type") && schema["type"].is_string()) << path << ": " << schema.dump();
  if (schema["type"] == "array") return ExpectFoxgloveReadable(schema["items"], path + "[]");
  if (schema["type"] != "object") return;
  ASSERT_TRUE(schema.contains("properties") && schema["properties"].is_object())
      << path << ": " << schema.dump();
  for (const auto& [name, property] : schema["properties"].items())
    ExpectFoxgloveReadable(property, path + "." + name);
}

TEST(FoxgloveMessages, AdvertisesSevenChannelsWithSchemas) {
  const json a = Advertise();
  EXPECT_EQ(a["op"], "advertise");
  ASSERT_EQ(a["channels"].size(), 7u);
  const std::vector<std::pair<std::string, std::string>> expected = {
      {"/tf", "foxglove.FrameTransforms"},         {"/scene", "foxglove.SceneUpdate"},
      {"/hmd/camera", "foxglove.CompressedImage"}, {"/reflective", "foxglove.CompressedImage"},
      {"/registration", "orbed.Registration"},     {"/guidance", "orbed.Guidance"},
      {"/fixed_view", "foxglove.CompressedImage"}};
  for (size_t i = 0; i < expected.size(); ++i) {
    const json& c = a["channels"][i];
    EXPECT_EQ(c["id"], i + 1);
    EXPECT_EQ(c["topic"], expected[i].first);
    EXPECT_EQ(c["schemaName"], expected[i].second);
    EXPECT_EQ(c["encoding"], "json");
    const json schema = json::parse(c["schema"].get<std::string>());
    EXPECT_EQ(schema["type"], "object");
    ExpectFoxgloveReadable(schema, c["topic"]);
  }
  EXPECT_EQ(ServerInfo("s")["supportedEncodings"], json::array({"json"}));
}

TEST(FoxgloveMessages, FramesOfBothRobots) {
  const sim::RobotModel model =
      sim::RobotModel::LoadFile(SourceTreePath(sim::RobotModel::kDefaultUrdfRelativePath));
  Eigen::Isometry3d X_WR = Eigen::Isometry3d::Identity();
  X_WR.translation() = Eigen::Vector3d(1, 2, 0.5);
  Eigen::Isometry3d X_WV = X_WR;
  X_WV.translation().x() += 0.01;
  const Eigen::VectorXd q = Eigen::VectorXd::Zero(model.num_joints());
  const json tf = FrameTransforms(RobotFrames(model, X_WR, q, X_WV, q), 1'500'000);
  const json& t = tf["transforms"];
  ASSERT_EQ(t.size(), 2u + 2u * static_cast<size_t>(model.num_links()));
  EXPECT_EQ(t[0]["parent_frame_id"], "W");
  EXPECT_EQ(t[0]["child_frame_id"], "R");
  EXPECT_EQ(t[0]["translation"]["y"], 2.0);
  EXPECT_EQ(t[0]["timestamp"]["sec"], 1);
  EXPECT_EQ(t[0]["timestamp"]["nsec"], 500'000'000);
  bool flange = false, virtual_flange = false;
  for (const json& f : t) {
    if (f["child_frame_id"] == "iiwa_link_ee") {
      flange = true;
      EXPECT_EQ(f["parent_frame_id"], "R");
      EXPECT_NEAR(f["translation"]["z"].get<double>(), 1.266, 1e-12);  // 0.34 + 0.4 + 0.4 + 0.126 m
      EXPECT_NEAR(f["rotation"]["w"].get<double>(), 1.0, 1e-12);
    }
    if (f["child_frame_id"] == "virtual/iiwa_link_ee") virtual_flange = f["parent_frame_id"] == "V";
  }
  EXPECT_TRUE(flange && virtual_flange);
  const json scene = SceneUpdate(model, nullptr, true, 0);
  size_t real = 0, virtual_links = 0;
  for (const json& e : scene["entities"]) {
    const std::string frame = e["frame_id"];
    (frame.rfind("virtual/", 0) == 0 ? virtual_links : real) += 1;
    EXPECT_TRUE(e["frame_locked"].get<bool>());
  }
  EXPECT_GT(real, 7u);
  EXPECT_EQ(real, virtual_links);
}

TEST(FoxgloveMessages, MessageDataAndBase64ByHand) {
  const std::string frame = MessageData(0x01020304, 0x0807060504030201ULL, "{}");
  const std::string expected("\x01\x04\x03\x02\x01\x01\x02\x03\x04\x05\x06\x07\x08{}", 15);
  EXPECT_EQ(frame, expected);
  const auto b64 = [](const std::string& s) {
    return CompressedImage(std::vector<uint8_t>(s.begin(), s.end()), "jpeg", "C", 0)["data"]
        .get<std::string>();
  };
  EXPECT_EQ(b64(""), "");
  EXPECT_EQ(b64("f"), "Zg==");
  EXPECT_EQ(b64("fo"), "Zm8=");
  EXPECT_EQ(b64("foobar"), "Zm9vYmFy");
}

TEST(FoxgloveMessages, ClientMessagesReadAndRefused) {
  std::string reason;
  ClientRequest r =
      ParseClientMessage(R"({"op":"subscribe","subscriptions":[{"id":7,"channelId":1}]})", &reason);
  EXPECT_TRUE(reason.empty()) << reason;
  ASSERT_EQ(r.kind, ClientRequest::kSubscribe);
  EXPECT_EQ(r.subscribe, (std::vector<std::pair<uint32_t, uint32_t>>{{7, 1}}));
  r = ParseClientMessage(R"({"op":"unsubscribe","subscriptionIds":[7, 8]})", &reason);
  ASSERT_EQ(r.kind, ClientRequest::kUnsubscribe);
  EXPECT_EQ(r.unsubscribe, (std::vector<uint32_t>{7, 8}));
  for (const std::string& bad :
       {std::string("not json"), std::string("[1]"),
        std::string(R"({"op":"subscribe","subscriptions":[{"id":-1,"channelId":1}]})"),
        std::string(R"({"op":"subscribe","subscriptions":[{"id":4294967296,"channelId":1}]})"),
        std::string(R"({"op":"unsubscribe","subscriptionIds":"all"})"),
        std::string(1000, '[') + std::string(1000, ']'), std::string(70000, ' ')}) {
    r = ParseClientMessage(bad, &reason);
    EXPECT_FALSE(reason.empty()) << bad.substr(0, 60);
    EXPECT_EQ(r.kind, ClientRequest::kIgnored);
  }
  r = ParseClientMessage(R"({"op":"getParameters"})", &reason);
  EXPECT_TRUE(reason.empty());
  EXPECT_EQ(r.op, "getParameters");
}

using Client = websocketpp::client<websocketpp::config::asio_client>;

struct TestClient {
  Client client;
  websocketpp::connection_hdl handle;
  std::vector<std::string> texts, binaries;
  bool open = false, failed = false;
  explicit TestClient(int port, const std::string& subprotocol) {
    client.clear_access_channels(websocketpp::log::alevel::all);
    client.clear_error_channels(websocketpp::log::elevel::all);
    client.init_asio();
    client.set_open_handler([this](websocketpp::connection_hdl) { open = true; });
    client.set_fail_handler([this](websocketpp::connection_hdl) { failed = true; });
    client.set_message_handler([this](websocketpp::connection_hdl, Client::message_ptr m) {
      (m->get_opcode() == websocketpp::frame::opcode::text ? texts : binaries).push_back(m->get_payload());
    });
    std::error_code ec;
    Client::connection_ptr con = client.get_connection("ws://127.0.0.1:" + std::to_string(port), ec);
    if (!subprotocol.empty()) con->add_subprotocol(subprotocol);
    handle = con->get_handle();
    client.connect(con);
  }
  void Send(const std::string& text) { client.send(handle, text, websocketpp::frame::opcode::text); }
};

// Polls server and client until `done` (at most 10 s of polling rounds).
bool Until(FoxgloveServer& server, TestClient& client, const std::function<bool()>& done) {
  for (int i = 0; i < 20000 && !done(); ++i) {
    server.Poll();
    client.client.poll();
    if (i % 100 == 99) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  return done();
}

TEST(FoxgloveServer, SubprotocolServerInfoSubscriptions) {
  std::vector<ServerEvent> events;
  ServerOptions options;
  options.port = 0;
  FoxgloveServer server(options, [&](const ServerEvent& e) { events.push_back(e); });
  ASSERT_GT(server.port(), 0);

  TestClient stranger(server.port(), "");
  ASSERT_TRUE(Until(server, stranger, [&] { return stranger.failed || stranger.open; }));
  EXPECT_TRUE(stranger.failed);
  ASSERT_FALSE(events.empty());
  EXPECT_NE(events.back().detail.find("subprotocol"), std::string::npos);

  TestClient client(server.port(), kSubprotocol);
  ASSERT_TRUE(Until(server, client, [&] { return client.texts.size() >= 2; }));
  EXPECT_EQ(json::parse(client.texts[0])["op"], "serverInfo");
  EXPECT_EQ(json::parse(client.texts[1])["op"], "advertise");
  EXPECT_FALSE(server.HasSubscribers(kTf));
  client.Send(R"({"op":"subscribe","subscriptions":[{"id":42,"channelId":1}]})");
  ASSERT_TRUE(Until(server, client, [&] { return server.HasSubscribers(kTf); }));
  EXPECT_EQ(server.Publish(kTf, 123, R"({"transforms":[]})"), 0);
  EXPECT_EQ(server.Publish(kScene, 123, "{}"), 0);  // nobody subscribed: nothing sent
  ASSERT_TRUE(Until(server, client, [&] { return !client.binaries.empty(); }));
  ASSERT_EQ(client.binaries.size(), 1u);
  EXPECT_EQ(client.binaries[0], MessageData(42, 123, R"({"transforms":[]})"));
  client.Send(R"({"op":"unsubscribe","subscriptionIds":[42]})");
  ASSERT_TRUE(Until(server, client, [&] { return !server.HasSubscribers(kTf); }));
  client.Send("nonsense");
  ASSERT_TRUE(Until(server, client, [&] {
    return !events.empty() && events.back().kind == ServerEvent::kRefused &&
           events.back().detail.find("client message") != std::string::npos;
  }));
  // Every advertised channel can be subscribed to (the last one too); the next id is no channel.
  const json advertised = Advertise()["channels"];
  const int last = advertised.back()["id"].get<int>();
  EXPECT_EQ(last, static_cast<int>(kLastChannel));
  client.Send(R"({"op":"subscribe","subscriptions":[{"id":43,"channelId":)" + std::to_string(last) + "}]}");
  ASSERT_TRUE(Until(server, client, [&] { return server.HasSubscribers(kFixedView); }));
  client.Send(R"({"op":"subscribe","subscriptions":[{"id":44,"channelId":)" + std::to_string(last + 1) +
              "}]}");
  ASSERT_TRUE(Until(server, client, [&] {
    return !events.empty() && events.back().kind == ServerEvent::kRefused &&
           events.back().detail.find("no channel " + std::to_string(last + 1)) != std::string::npos;
  }));
}

}  // namespace
}  // namespace orbed::foxglove
