#pragma once
/// @file
/// `orbed-log export LOG OUT.mcap --mcap`: an LCM event log as an MCAP file that Foxglove opens
/// offline (File > Open), chunked and indexed, written by @mcap/core's McapWriter (npm, run by node:
/// procs/logger/mcap/mcap_writer.mjs, installed into the build tree by the target mcap_writer).
///
/// What the file holds (all messages "json", all schemas "jsonschema"):
///   - the Foxglove bridge's channels (sim/foxglove_messages.h: the same schemas and the same JSON),
///     made from the log as the bridge makes them from the bus: /tf (every frame, from the log's
///     ROBOT_STATE at most tf_hz, with the latest HMD_POSE, REGISTRATION, GUIDANCE target and
///     FIXED_VIEW camera), /scene (with the first /tf, every scene_period_s and when the virtual
///     robot appears), /hmd/camera, /reflective and /fixed_view (every JPEG the log has, not the
///     bridge's image_hz), /registration and /guidance (every valid one). Inputs the bridge would
///     refuse are refused here with its reasons;
///   - every LCM channel of a known type (the fingerprints of csv_export.h) under its own name, each
///     message as JSON with the JSON Schema of its type generated from the .lcm file
///     (lcmtypes/gen_json.py: int64 exact, NaN and infinities null, byte arrays base64,
///     multi-dimensional arrays row-major). A channel's type is that of its first message that
///     decodes (DecodeBounded); messages of another type there, or that do not decode, are counted
///     by reason and not written; channels of no known type are listed and skipped;
///   - metadata "provenance": the run's provenance record (provenance.json beside the log, if
///     there is one, at most kMaxProvenanceBytes), one entry per top-level key (strings as they
///     are, anything else as its JSON text); metadata "orbed.export": the log's name and the cut.
/// Every message's log time and publish time is its event's timestamp in the log [ns]; the JSON's
/// own times (utime, timestamp) are the messages' own, as on the bus (/tf and /scene: the event's).
///
/// The core (WriteMcapRecords) makes the records in log order and hands them to a RecordSink; the
/// shell (ExportMcap) frames them onto a pipe into node. One pass over the log; memory O(channels)
/// here, O(messages) in the writer's index.
///
/// Threading: single-threaded.

#include <cstdint>
#include <map>
#include <regex>
#include <string>
#include <vector>

#include "procs/logger/event_log_reader.h"
#include "sim/robot_model.h"
#include "sim/scene.h"

namespace orbed::logger {

struct McapExportOptions {
  std::string out_path;            ///< the MCAP file (replaced when the export succeeds)
  double from_s = 0, to_s = 1e18;  ///< seconds after the log's first event
  std::regex channels{".*"};       ///< whole LCM channel name must match
  std::string provenance_path;     ///< "" = none
  std::string log_name;            ///< for the metadata
  /// The Foxglove channels' robot and scene: "" = the shipped robot, and the scene the run was
  /// launched with (the provenance record's arguments) or else the shipped OR.
  std::string urdf_path, scene_path;
  double tf_hz = 30.0, scene_period_s = 1.0;
};

inline constexpr size_t kMaxProvenanceBytes = 16 << 20;
/// LCM channels beyond this many (in the order they first appear) are left out and counted: MCAP
/// channel ids are 16-bit, and a hostile log must not make a map of millions of names.
inline constexpr size_t kMaxMcapChannels = 4096;

/// One record for the MCAP file. Ids are this export's, from 1, in the order they are handed out.
struct McapSchemaRecord {
  uint16_t id = 0;
  std::string name, encoding, data;
};
struct McapChannelRecord {
  uint16_t id = 0, schema_id = 0;
  std::string topic, message_encoding;
  std::map<std::string, std::string> metadata;
};
struct McapMessageRecord {
  uint16_t channel_id = 0;
  uint32_t sequence = 0;
  uint64_t log_time_ns = 0, publish_time_ns = 0;
  std::string data;
};
struct McapMetadataRecord {
  std::string name;
  std::map<std::string, std::string> metadata;
};

class RecordSink {
 public:
  virtual ~RecordSink() = default;
  /// Each returns false when the sink failed (the export stops).
  virtual bool Add(const McapSchemaRecord& r) = 0;
  virtual bool Add(const McapChannelRecord& r) = 0;
  virtual bool Add(const McapMessageRecord& r) = 0;
  virtual bool Add(const McapMetadataRecord& r) = 0;
};

/// What went into the file, per LCM channel and per Foxglove topic.
struct McapChannelResult {
  std::string channel, type;  ///< type empty when no message of a known type decoded
  int64_t messages = 0;
  int64_t unknown = 0;                     ///< events with no known fingerprint
  std::map<std::string, int64_t> refused;  ///< reason → events not written (or not shown in Foxglove)
};
struct McapExportResult {
  std::vector<McapChannelResult> channels;  ///< LCM channels, in name order
  std::map<std::string, int64_t> topics;    ///< Foxglove topic → messages
  int64_t events_on_channels_left_out = 0;  ///< events of the channels beyond kMaxMcapChannels
  bool provenance = false;                  ///< the provenance record went in
  std::string provenance_problem;           ///< why a provenance file was left out
  std::string error;
  bool ok() const { return error.empty(); }
};

/// The records of `log` into `sink` (pure but for reading the provenance file, the model and scene).
McapExportResult WriteMcapRecords(const MappedLog& log, const McapExportOptions& options, RecordSink* sink);
/// The same on log bytes in memory with the robot and scene given (`scene` may be null); the
/// provenance file is read when options name one. The fuzz target's entry (fuzz_event_log).
McapExportResult WriteMcapRecords(const uint8_t* data, size_t size, const McapExportOptions& options,
                                  const sim::RobotModel& model, const sim::Scene* scene, RecordSink* sink);

/// Writes options.out_path through node and the MCAP writer (see the file comment).
McapExportResult ExportMcap(const MappedLog& log, const McapExportOptions& options);

}  // namespace orbed::logger
