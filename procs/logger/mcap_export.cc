#include "procs/logger/mcap_export.h"

#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <exception>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>

#include <orbed/all_types.hpp>
#include <orbed/to_json.hpp>

#include "base/format.h"
#include "base/source_paths.h"
#include "lcmtypes/bounded_decode.h"
#include "lcmtypes/contract/channels.h"
#include "lcmtypes/contract/conversions.h"
#include "lcmtypes/contract/validation.h"
#include "sim/foxglove_messages.h"
#include "sim/testbed_poses.h"

extern char** environ;

namespace orbed::logger {
namespace {

using json = nlohmann::json;

class Exporter;

// One message type: its fingerprint, name, JSON Schema and its decoder into the exporter.
struct MessageType {
  int64_t fingerprint;
  const char* name;
  const char* schema;
  // Decodes (DecodeBounded) and hands the message to the exporter; false with the reason's class.
  bool (*handle)(Exporter& exporter, const MessageType& type, const LogEvent& e, std::string* reason);
};

template <class Msg>
bool HandleAs(Exporter& exporter, const MessageType& type, const LogEvent& e, std::string* reason);

const std::vector<MessageType>& MessageTypes() {
#define ORBED_MESSAGE_TYPE(T)                                                                \
  {orbed::T::getHash(), #T, lcm_json::JsonSchemaText(static_cast<const orbed::T*>(nullptr)), \
   &HandleAs<orbed::T>},
  static const std::vector<MessageType> types = {ORBED_FOR_EACH_LCM_TYPE(ORBED_MESSAGE_TYPE)};
#undef ORBED_MESSAGE_TYPE
  return types;
}

const MessageType* TypeOf(const uint8_t* data, size_t size) {
  return FindTypeByFingerprint(MessageTypes(), data, size);
}

std::string Hex(int64_t fingerprint) {
  char text[20];
  std::snprintf(text, sizeof(text), "%016llx", static_cast<unsigned long long>(fingerprint));
  return text;
}

// The walk over the log: the LCM channels as JSON, the Foxglove channels from the testbed's poses.
class Exporter {
 public:
  Exporter(const McapExportOptions& options, const sim::RobotModel& model, const sim::Scene* scene,
           RecordSink* sink)
      : options_(options), sink_(sink), model_(model), scene_(scene), poses_(model_) {}

  void Metadata(const std::string& name, const std::map<std::string, std::string>& entries) {
    ok_ = ok_ && sink_->Add(McapMetadataRecord{name, entries});
  }

  void Event(const LogEvent& e) {
    if (channels_.size() >= kMaxMcapChannels && !channels_.count(e.channel)) {
      ++events_left_out_;
      return;
    }
    ChannelState& c = channels_[e.channel];
    if (c.result.channel.empty()) c.result.channel = e.channel;
    const MessageType* type = TypeOf(e.data, e.size);
    std::string reason;
    if (type == nullptr) {
      ++c.result.unknown;
    } else if (!type->handle(*this, *type, e, &reason)) {
      ++c.result.refused[reason];
    }
  }

  template <class Msg>
  void Decoded(const MessageType& type, const LogEvent& e, const Msg& msg) {
    ChannelState& c = channels_[e.channel];
    if (c.type == nullptr) {
      c.type = &type;
      c.result.type = type.name;
      c.id = Channel(e.channel, SchemaId(std::string("orbed.") + type.name, type.schema),
                     {{"lcm_type", type.name}, {"lcm_fingerprint", Hex(type.fingerprint)}});
    }
    if (c.type != &type) {
      ++c.result.refused[std::string("another type (") + type.name + ")"];
      return;
    }
    nlohmann::ordered_json j;
    lcm_json::ToJson(msg, j);
    Message(c.id, &c.sequence, e.timestamp_us, lcm_json::Dump(j));
    ++c.result.messages;
    Foxglove(e, msg);
  }

  bool ok() const { return ok_; }

  McapExportResult Result() const {
    McapExportResult result;
    for (const auto& [name, c] : channels_) result.channels.push_back(c.result);
    for (const auto& [id, t] : topics_) result.topics[t.topic] = t.messages;
    result.events_on_channels_left_out = events_left_out_;
    return result;
  }

 private:
  struct ChannelState {
    McapChannelResult result;
    const MessageType* type = nullptr;
    uint16_t id = 0;
    uint32_t sequence = 0;
  };
  struct TopicState {
    std::string topic;
    uint16_t id = 0;
    uint32_t sequence = 0;
    int64_t messages = 0;
  };

  uint16_t SchemaId(const std::string& name, const std::string& text) {
    const auto it = schema_ids_.find(name);
    if (it != schema_ids_.end()) return it->second;
    const auto id = static_cast<uint16_t>(schema_ids_.size() + 1);
    schema_ids_[name] = id;
    ok_ = ok_ && sink_->Add(McapSchemaRecord{id, name, "jsonschema", text});
    return id;
  }

  uint16_t Channel(const std::string& topic, uint16_t schema_id,
                   std::map<std::string, std::string> metadata) {
    const uint16_t id = next_channel_id_++;
    ok_ = ok_ && sink_->Add(McapChannelRecord{id, schema_id, topic, "json", std::move(metadata)});
    return id;
  }

  void Message(uint16_t channel_id, uint32_t* sequence, int64_t log_us, std::string data) {
    const uint64_t t_ns = static_cast<uint64_t>(std::max<int64_t>(log_us, 0)) * 1000;
    ok_ = ok_ && sink_->Add(McapMessageRecord{channel_id, (*sequence)++, t_ns, t_ns, std::move(data)});
  }

  // A message on a Foxglove channel (registered with its first message).
  void Send(foxglove::ChannelId id, int64_t log_us, const json& payload) {
    TopicState& t = topics_[id];
    if (t.id == 0) {
      const foxglove::ChannelSpec& spec = foxglove::Channels()[id - 1];
      t.topic = spec.topic;
      t.id = Channel(spec.topic, SchemaId(spec.schema_name, spec.schema.dump()), {});
    }
    Message(t.id, &t.sequence, log_us, payload.dump(-1, ' ', false, json::error_handler_t::replace));
    ++t.messages;
  }

  void Refuse(const LogEvent& e, const std::string& topic, const std::string& what) {
    ++channels_[e.channel].result.refused["not on " + topic + " (" + what + ")"];
  }

  // What the bridge would make of each message (procs/foxglove_bridge/foxglove_bridge_process.cc).
  template <class Msg>
  void Foxglove(const LogEvent&, const Msg&) {}

  void Foxglove(const LogEvent& e, const orbed::robot_state_t& msg) {
    if (e.channel != channels::kRobotState) return;
    if (!poses_.Update(msg).empty()) return Refuse(e, "/tf", "field");
    const int64_t t = e.timestamp_us;
    const bool with_virtual = poses_.X_WV().has_value();
    if (!last_scene_us_ || t - *last_scene_us_ >= static_cast<int64_t>(options_.scene_period_s * 1e6) ||
        with_virtual != scene_with_virtual_) {
      Send(foxglove::kScene, t, foxglove::SceneUpdate(model_, scene_, with_virtual, t));
      last_scene_us_ = t;
      scene_with_virtual_ = with_virtual;
    }
    if (last_tf_us_ && t - *last_tf_us_ < static_cast<int64_t>(1e6 / options_.tf_hz)) return;
    std::vector<foxglove::Frame> frames =
        foxglove::RobotFrames(model_, *poses_.X_WR(), poses_.q(), poses_.X_WV(), poses_.q_virtual());
    if (poses_.X_WH()) frames.push_back({"W", "H", *poses_.X_WH()});
    if (poses_.X_WC()) frames.push_back({"W", "C", *poses_.X_WC()});
    if (X_WD_) frames.push_back({"W", "D", *X_WD_});
    Send(foxglove::kTf, t, foxglove::FrameTransforms(frames, t));
    last_tf_us_ = t;
  }

  void Foxglove(const LogEvent& e, const orbed::hmd_pose_t& msg) {
    if (e.channel != channels::kHmdPose) return;
    if (!poses_.Update(msg).empty()) Refuse(e, "/tf", "pose");
  }

  void Foxglove(const LogEvent& e, const orbed::registration_t& msg) {
    if (e.channel != channels::kRegistration) return;
    bool used = false;
    if (!poses_.Update(msg, &used).empty()) return Refuse(e, "/registration", "pose");
    if (used) Send(foxglove::kRegistration, e.timestamp_us, foxglove::Registration(msg, *poses_.X_WV()));
  }

  void Foxglove(const LogEvent& e, const orbed::guidance_t& msg) {
    if (e.channel != channels::kGuidance) return;
    if (!poses_.Update(msg).empty()) return Refuse(e, "/guidance", "field");
    Send(foxglove::kGuidance, e.timestamp_us, foxglove::Guidance(msg));
  }

  void Foxglove(const LogEvent& e, const orbed::image_t& msg) {
    const bool camera = e.channel == channels::kHmdCamera, fixed = e.channel == channels::kFixedView;
    if (!camera && !fixed) return;
    const foxglove::ChannelId id = camera ? foxglove::kCamera : foxglove::kFixedView;
    const std::string topic = foxglove::Channels()[id - 1].topic;
    if (fixed) {
      if (!CheckPose(msg.X_WC, "FIXED_VIEW.X_WC").empty()) return Refuse(e, topic, "pose");
      X_WD_ = FromPose(msg.X_WC);
    }
    if (!foxglove::ImageProblem(msg).empty()) return Refuse(e, topic, "image");
    Send(id, e.timestamp_us, foxglove::CompressedImage(msg.data, "jpeg", camera ? "C" : "D", msg.utime));
  }

  void Foxglove(const LogEvent& e, const orbed::reflective_view_t& msg) {
    if (e.channel != channels::kReflectiveView) return;
    if (msg.display_id < 0 || msg.display_id > 999) return Refuse(e, "/reflective", "field");
    if (!foxglove::ImageProblem(msg.image).empty()) return Refuse(e, "/reflective", "image");
    Send(foxglove::kReflective, e.timestamp_us,
         foxglove::CompressedImage(msg.image.data, "jpeg", "reflective_" + std::to_string(msg.display_id),
                                   msg.image.utime));
  }

  const McapExportOptions& options_;
  RecordSink* sink_;
  bool ok_ = true;
  const sim::RobotModel& model_;
  const sim::Scene* scene_;
  sim::TestbedPoseState poses_;
  std::optional<Eigen::Isometry3d> X_WD_;
  std::optional<int64_t> last_tf_us_, last_scene_us_;
  bool scene_with_virtual_ = false;
  std::map<std::string, ChannelState> channels_;
  std::map<uint32_t, TopicState> topics_;
  std::map<std::string, uint16_t> schema_ids_;
  uint16_t next_channel_id_ = 1;
  int64_t events_left_out_ = 0;
};

template <class Msg>
bool HandleAs(Exporter& exporter, const MessageType& type, const LogEvent& e, std::string* reason) {
  Msg msg;
  const DecodeResult decoded = DecodeBounded(e.data, e.size, &msg);
  if (!decoded.ok()) {
    *reason = wire::KindName(decoded.kind);
    return false;
  }
  exporter.Decoded(type, e, msg);
  return true;
}

// The provenance record as metadata entries, or why it is left out.
std::map<std::string, std::string> ProvenanceEntries(const std::string& path, std::string* problem) {
  std::map<std::string, std::string> entries;
  std::error_code ec;
  const auto bytes = std::filesystem::file_size(path, ec);
  if (ec || bytes > kMaxProvenanceBytes) {
    *problem = ec ? "cannot read it" : "larger than " + std::to_string(kMaxProvenanceBytes) + " bytes";
    return entries;
  }
  std::ifstream in(path, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  const json doc = json::parse(text.str(), nullptr, false);
  if (doc.is_discarded() || !doc.is_object()) {
    *problem = "not a JSON object";
    return entries;
  }
  for (const auto& [key, value] : doc.items())
    entries[key] = value.is_string() ? value.get<std::string>()
                                     : value.dump(-1, ' ', false, json::error_handler_t::replace);
  return entries;
}

// The scene the run was launched with (the provenance record's "arguments"."scene", a path in the
// source tree or absolute), or "" when the record names none or cannot be read.
std::string SceneOfRun(const std::string& provenance_path) {
  std::string problem;
  const std::map<std::string, std::string> entries = ProvenanceEntries(provenance_path, &problem);
  const auto arguments = entries.find("arguments");
  if (!problem.empty() || arguments == entries.end()) return "";
  const json parsed = json::parse(arguments->second, nullptr, false);
  if (!parsed.is_object() || !parsed.contains("scene") || !parsed["scene"].is_string()) return "";
  const std::string scene = parsed["scene"].get<std::string>();
  if (scene.empty() || std::filesystem::path(scene).is_absolute()) return scene;
  return SourceTreePath(scene);
}

// Frames records onto a pipe into the node writer (procs/logger/mcap/mcap_writer.mjs says the frame).
class PipeSink : public RecordSink {
 public:
  explicit PipeSink(int fd) : fd_(fd) {}
  bool Add(const McapSchemaRecord& r) override {
    return Frame('S', json{{"id", r.id}, {"name", r.name}, {"encoding", r.encoding}}.dump(), r.data);
  }
  bool Add(const McapChannelRecord& r) override {
    return Frame('C',
                 json{{"id", r.id},
                      {"schemaId", r.schema_id},
                      {"topic", r.topic},
                      {"messageEncoding", r.message_encoding},
                      {"metadata", r.metadata}}
                     .dump(-1, ' ', false, json::error_handler_t::replace),
                 "");
  }
  bool Add(const McapMessageRecord& r) override {
    return Frame('M',
                 json{{"channelId", r.channel_id},
                      {"sequence", r.sequence},
                      {"logTime", std::to_string(r.log_time_ns)},
                      {"publishTime", std::to_string(r.publish_time_ns)}}
                     .dump(),
                 r.data);
  }
  /// The last frame: the export is whole (without it the writer leaves no file).
  bool End() { return Frame('E', "{}", ""); }
  bool Add(const McapMetadataRecord& r) override {
    return Frame(
        'D',
        json{{"name", r.name}, {"metadata", r.metadata}}.dump(-1, ' ', false, json::error_handler_t::replace),
        "");
  }

 private:
  static void AppendU32(std::string* s, size_t n) {
    for (int i = 0; i < 4; ++i) s->push_back(static_cast<char>((n >> (8 * i)) & 0xff));
  }
  bool Frame(char kind, const std::string& header, const std::string& body) {
    if (body.size() > 0xffffffffu) return false;
    std::string head(1, kind);
    AppendU32(&head, header.size());
    head += header;
    AppendU32(&head, body.size());
    return Write(head) && Write(body);
  }
  bool Write(const std::string& bytes) {
    size_t done = 0;
    while (done < bytes.size()) {
      const ssize_t n = ::write(fd_, bytes.data() + done, bytes.size() - done);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) return false;
      done += static_cast<size_t>(n);
    }
    return true;
  }
  int fd_;
};

}  // namespace

McapExportResult WriteMcapRecords(const MappedLog& log, const McapExportOptions& options, RecordSink* sink) {
  const sim::RobotModel model = sim::RobotModel::LoadFlag(options.urdf_path);
  // The run's own scene when none is given (a study's patients each have theirs).
  const std::string scene_path = options.scene_path.empty() && !options.provenance_path.empty()
                                     ? SceneOfRun(options.provenance_path)
                                     : options.scene_path;
  const std::optional<sim::Scene> scene = sim::LoadSceneFlag(scene_path);
  return WriteMcapRecords(log.data(), log.size(), options, model, scene ? &*scene : nullptr, sink);
}

McapExportResult WriteMcapRecords(const uint8_t* data, size_t size, const McapExportOptions& options,
                                  const sim::RobotModel& model, const sim::Scene* scene, RecordSink* sink) {
  McapExportResult result;
  Exporter exporter(options, model, scene, sink);
  std::map<std::string, std::string> provenance;
  if (!options.provenance_path.empty()) {
    provenance = ProvenanceEntries(options.provenance_path, &result.provenance_problem);
    if (result.provenance_problem.empty()) exporter.Metadata("provenance", provenance);
  }
  exporter.Metadata("orbed.export", {{"log", options.log_name},
                                     {"from_s", ShortestDecimal(options.from_s)},
                                     {"to_s", ShortestDecimal(options.to_s)}});
  EventLogScanner scanner(data, size);
  LogEvent e;
  EventWindow window(options.from_s, options.to_s, options.channels);
  while (exporter.ok() && scanner.Next(&e))
    if (window.Take(e)) exporter.Event(e);
  const std::string problem = result.provenance_problem;
  result = exporter.Result();
  result.provenance_problem = problem;
  result.provenance = !options.provenance_path.empty() && problem.empty();
  if (!exporter.ok()) result.error = "the MCAP writer stopped reading";
  return result;
}

McapExportResult ExportMcap(const MappedLog& log, const McapExportOptions& options) {
  McapExportResult result;
  const std::filesystem::path writer_dir = ORBED_MCAP_WRITER_DIR;
  const std::string script = (writer_dir / "mcap_writer.mjs").string();
  if (!std::filesystem::exists(script) || !std::filesystem::exists(writer_dir / "node_modules/@mcap/core")) {
    result.error = "the MCAP writer is not installed in " + writer_dir.string() +
                   ": build it with `cmake --build build --target mcap_writer`";
    return result;
  }
  int fds[2];
  if (::pipe(fds) != 0) {
    result.error = std::string("pipe: ") + std::strerror(errno);
    return result;
  }
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, fds[0], 0);
  posix_spawn_file_actions_addclose(&actions, fds[0]);
  posix_spawn_file_actions_addclose(&actions, fds[1]);
  std::string node = ORBED_NODE, out = options.out_path;
  std::vector<char*> argv = {node.data(), const_cast<char*>(script.c_str()), out.data(), nullptr};
  pid_t pid = 0;
  const int spawned = posix_spawn(&pid, node.c_str(), &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  ::close(fds[0]);
  if (spawned != 0) {
    ::close(fds[1]);
    result.error = "cannot start " + node + ": " + std::strerror(spawned);
    return result;
  }
  // A writer that died must not kill this process with SIGPIPE: its exit code says what happened.
  struct sigaction ignore {
  }, previous{};
  ignore.sa_handler = SIG_IGN;
  sigaction(SIGPIPE, &ignore, &previous);
  try {
    PipeSink sink(fds[1]);
    result = WriteMcapRecords(log, options, &sink);
    if (result.ok() && !sink.End()) result.error = "the MCAP writer stopped reading";
  } catch (const std::exception& e) {
    result.error = e.what();
  }
  ::close(fds[1]);
  int status = 0;
  while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  sigaction(SIGPIPE, &previous, nullptr);
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    const std::string how = WIFEXITED(status) ? "exit code " + std::to_string(WEXITSTATUS(status))
                                              : "signal " + std::to_string(WTERMSIG(status));
    if (result.error.empty() || result.error == "the MCAP writer stopped reading")
      result.error = "the MCAP writer (node " + script + ") failed: " + how;
  }
  return result;
}

}  // namespace orbed::logger
