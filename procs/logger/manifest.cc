#include "procs/logger/manifest.h"

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <limits>
#include <set>

#include <nlohmann/json.hpp>

#include "base/format.h"
#include "base/json.h"
#include "base/replace_file.h"
#include "procs/logger/event_log_reader.h"
#include "procs/logger/event_log_writer.h"

namespace orbed::logger {
namespace {

constexpr int kMaxDepth = 8;
constexpr int64_t kMaxCount = std::numeric_limits<int64_t>::max();
constexpr size_t kMaxText = 1 << 16;

std::string UtcTime(int64_t utime) { return FormatUtc(utime, "%Y-%m-%dT%H:%M:%SZ"); }

void WriteChannels(JsonWriter* json, const std::map<std::string, ChannelStats>& channels) {
  json->BeginObject();
  for (const auto& [channel, stats] : channels) {
    json->Key(channel).BeginObject();
    json->Key("events").Int(stats.events);
    json->Key("bytes").Int(stats.bytes);
    json->Key("first_utime").Int(stats.first_utime);
    json->Key("last_utime").Int(stats.last_utime);
    json->EndObject();
  }
  json->EndObject();
}

std::map<std::string, ChannelStats> ReadChannels(const JsonFields& f, const JsonAt& at) {
  std::map<std::string, ChannelStats> channels;
  for (const auto& [name, value] : f.Members(at, kMaxChannels)) {
    if (name.empty() || name.size() > kMaxLogChannelBytes)
      f.Fail(value.key, "a channel name of 1 to 256 bytes");
    ChannelStats stats;
    stats.events = f.Integer(f.Member(value, "events"), 1, kMaxCount);
    stats.bytes = f.Integer(f.Member(value, "bytes"), 0, kMaxCount);
    stats.first_utime = f.Integer(f.Member(value, "first_utime"), 0, kMaxCount);
    stats.last_utime = f.Integer(f.Member(value, "last_utime"), stats.first_utime, kMaxCount);
    channels[name] = stats;
  }
  return channels;
}

// Sums that cannot overflow: every term was read within [0, INT64_MAX]; a sum beyond it is refused.
int64_t Add(const JsonFields& f, const std::string& key, int64_t a, int64_t b) {
  if (b > kMaxCount - a) f.Fail(key, "sums within 64 bits");
  return a + b;
}

}  // namespace

void Accumulate(const ChannelStats& more, ChannelStats* into) {
  if (more.events == 0) return;
  into->first_utime = into->events == 0 ? more.first_utime : std::min(into->first_utime, more.first_utime);
  into->last_utime = into->events == 0 ? more.last_utime : std::max(into->last_utime, more.last_utime);
  into->events += more.events;
  into->bytes += more.bytes;
}

int64_t Manifest::events() const {
  int64_t total = 0;
  for (const ManifestPart& part : parts) total += part.events;
  return total;
}

int64_t Manifest::bytes() const {
  int64_t total = 0;
  for (const ManifestPart& part : parts) total += part.bytes;
  return total;
}

int64_t Manifest::drops() const {
  int64_t total = 0;
  for (const ManifestPart& part : parts) total += part.drops;
  return total;
}

std::map<std::string, ChannelStats> Manifest::channels() const {
  std::map<std::string, ChannelStats> total;
  for (const ManifestPart& part : parts) {
    for (const auto& [channel, stats] : part.channels) Accumulate(stats, &total[channel]);
  }
  return total;
}

std::string ManifestJson(const Manifest& m) {
  JsonWriter json(2);
  json.BeginObject();
  json.Key("log_file").String(m.parts.empty() ? "" : m.parts.front().file);
  json.Key("complete").Bool(m.complete);
  json.Key("start_utime").Int(m.start_utime);
  json.Key("start_time_utc").String(UtcTime(m.start_utime));
  if (m.stop_utime) {
    json.Key("stop_utime").Int(*m.stop_utime);
    json.Key("stop_time_utc").String(UtcTime(*m.stop_utime));
  }
  json.Key("command_line").String(m.command_line);
  json.Key("versions").BeginObject();
  json.Key("orbed").String(m.orbed_version);
  json.Key("lcm").String(m.lcm_version);
  json.EndObject();
  json.Key("lcm_url").String(m.lcm_url);
  json.Key("channels_regex").String(m.channels_regex);
  json.Key("files").BeginArray();
  for (const HashedFile& file : m.files) {
    json.BeginObject();
    json.Key("path").String(file.path);
    if (file.sha256.empty()) {
      json.Key("error").String(file.error);
    } else {
      json.Key("sha256").String(file.sha256);
    }
    json.EndObject();
  }
  json.EndArray();
  json.Key("parts").BeginArray();
  for (const ManifestPart& part : m.parts) {
    json.BeginObject();
    json.Key("file").String(part.file);
    json.Key("start_utime").Int(part.start_utime);
    if (part.stop_utime) json.Key("stop_utime").Int(*part.stop_utime);
    json.Key("complete").Bool(part.complete);
    json.Key("events").Int(part.events);
    json.Key("bytes").Int(part.bytes);
    json.Key("drops").Int(part.drops);
    json.Key("damaged_bytes").Int(part.damaged_bytes);
    json.Key("channels");
    WriteChannels(&json, part.channels);
    if (!part.error.empty()) json.Key("error").String(part.error);
    json.EndObject();
  }
  json.EndArray();
  json.Key("events_written").Int(m.events());
  json.Key("bytes_written").Int(m.bytes());
  json.Key("drops").Int(m.drops());
  json.Key("channels");
  WriteChannels(&json, m.channels());
  json.EndObject();
  return json.str() + "\n";
}

Manifest ParseManifest(const std::string& text, const std::string& source) {
  const JsonFields f(source);
  const nlohmann::json doc = f.Parse(text, kMaxManifestBytes, kMaxDepth);
  const JsonAt root{doc, ""};
  Manifest m;
  m.complete = f.Bool(f.Member(root, "complete"));
  m.start_utime = f.Integer(f.Member(root, "start_utime"), 0, kMaxCount);
  if (const auto stop = f.OptionalMember(root, "stop_utime"))
    m.stop_utime = f.Integer(*stop, m.start_utime, kMaxCount);
  if (m.complete != m.stop_utime.has_value())
    f.Fail("stop_utime", m.complete ? "a stop time" : "no stop time");
  m.command_line = f.String(f.Member(root, "command_line"), kMaxText);
  const JsonAt versions = f.Member(root, "versions");
  m.orbed_version = f.String(f.Member(versions, "orbed"), kMaxText);
  m.lcm_version = f.String(f.Member(versions, "lcm"), kMaxText);
  m.lcm_url = f.String(f.Member(root, "lcm_url"), kMaxText);
  m.channels_regex = f.String(f.Member(root, "channels_regex"), kMaxText);
  const JsonAt files = f.Member(root, "files");
  for (size_t i = 0, n = f.ArraySize(files, kMaxParts); i < n; ++i) {
    const JsonAt file = f.Element(files, i);
    HashedFile hashed;
    hashed.path = f.String(f.Member(file, "path"), kMaxText);
    if (const auto sha = f.OptionalMember(file, "sha256")) {
      hashed.sha256 = f.String(*sha, 64);
      if (hashed.sha256.size() != 64 ||
          hashed.sha256.find_first_not_of("0123456789abcdef") != std::string::npos) {
        f.Fail(sha->key, "64 lowercase hex digits", &sha->value);
      }
    } else {
      hashed.error = f.String(f.Member(file, "error"), kMaxText);
    }
    m.files.push_back(hashed);
  }

  const JsonAt parts = f.Member(root, "parts");
  const size_t num_parts = f.ArraySize(parts, kMaxParts);
  if (num_parts == 0) f.Fail(parts.key, "at least one part");
  std::set<std::string> names;
  for (size_t i = 0; i < num_parts; ++i) {
    const JsonAt at = f.Element(parts, i);
    ManifestPart part;
    const JsonAt file = f.Member(at, "file");
    part.file = f.String(file, 255);
    if (part.file.empty() || part.file == "." || part.file == ".." ||
        part.file.find('/') != std::string::npos || part.file.find('\0') != std::string::npos ||
        !names.insert(part.file).second) {
      f.Fail(file.key, "a file name of its own (no '/')", &file.value);
    }
    part.start_utime = f.Integer(f.Member(at, "start_utime"), 0, kMaxCount);
    if (const auto stop = f.OptionalMember(at, "stop_utime"))
      part.stop_utime = f.Integer(*stop, 0, kMaxCount);
    part.complete = f.Bool(f.Member(at, "complete"));
    if (part.complete && !(i + 1 == num_parts && m.complete)) {
      f.Fail(at.key + ".complete", "false: only the last part of a complete recording is complete");
    }
    part.events = f.Integer(f.Member(at, "events"), 0, kMaxCount);
    part.bytes = f.Integer(f.Member(at, "bytes"), 0, kMaxCount);
    part.drops = f.Integer(f.Member(at, "drops"), 0, kMaxCount);
    part.damaged_bytes = f.Integer(f.Member(at, "damaged_bytes"), 0, kMaxCount);
    part.channels = ReadChannels(f, f.Member(at, "channels"));
    if (const auto error = f.OptionalMember(at, "error")) part.error = f.String(*error, kMaxText);
    // The part's totals are its channels' (bytes: each event's header and channel name too).
    int64_t events = 0, bytes = 0;
    for (const auto& [name, stats] : part.channels) {
      events = Add(f, at.key + ".events", events, stats.events);
      const int64_t per_event = static_cast<int64_t>(EventLogWriter::kHeaderBytes + name.size());
      if (stats.events > kMaxCount / per_event) f.Fail(at.key + ".bytes", "sums within 64 bits");
      bytes =
          Add(f, at.key + ".bytes", Add(f, at.key + ".bytes", bytes, stats.events * per_event), stats.bytes);
    }
    if (events != part.events)
      f.Fail(at.key + ".events", "the sum of its channels' events, " + std::to_string(events));
    if (bytes != part.bytes) f.Fail(at.key + ".bytes", "its events' bytes, " + std::to_string(bytes));
    m.parts.push_back(part);
  }
  if (m.complete && !m.parts.back().complete)
    f.Fail(parts.key, "a complete last part in a complete recording");
  if (m.parts.front().start_utime != m.start_utime)
    f.Fail("parts[0].start_utime", "the recording's start_utime");

  // The sums over the parts.
  int64_t events = 0, bytes = 0, drops = 0;
  for (const ManifestPart& part : m.parts) {
    events = Add(f, "events_written", events, part.events);
    bytes = Add(f, "bytes_written", bytes, part.bytes);
    drops = Add(f, "drops", drops, part.drops);
  }
  if (f.Integer(f.Member(root, "events_written"), 0, kMaxCount) != events) {
    f.Fail("events_written", "the parts' sum, " + std::to_string(events));
  }
  if (f.Integer(f.Member(root, "bytes_written"), 0, kMaxCount) != bytes) {
    f.Fail("bytes_written", "the parts' sum, " + std::to_string(bytes));
  }
  if (f.Integer(f.Member(root, "drops"), 0, kMaxCount) != drops)
    f.Fail("drops", "the parts' sum, " + std::to_string(drops));
  const std::map<std::string, ChannelStats> channels = ReadChannels(f, f.Member(root, "channels"));
  const std::map<std::string, ChannelStats> sums = m.channels();
  if (channels.size() != sums.size()) f.Fail("channels", "the channels of the parts");
  for (const auto& [name, stats] : sums) {
    const auto it = channels.find(name);
    if (it == channels.end() || it->second.events != stats.events || it->second.bytes != stats.bytes ||
        it->second.first_utime != stats.first_utime || it->second.last_utime != stats.last_utime) {
      f.Fail("channels." + name, "the sum over the parts");
    }
  }
  if (f.String(f.Member(root, "log_file"), 255) != m.parts.front().file)
    f.Fail("log_file", "the first part's file");
  return m;
}

Manifest ReadManifestFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw JsonReadError(path + ": cannot read it");
  std::string text(kMaxManifestBytes + 1, '\0');
  in.read(text.data(), static_cast<std::streamsize>(text.size()));
  text.resize(static_cast<size_t>(in.gcount()));
  return ParseManifest(text, path);
}

bool WriteManifestFile(const std::string& path, const Manifest& manifest, std::string* error) {
  return ReplaceFile(path, ManifestJson(manifest), error);
}

std::string PartFileName(const std::string& first_file, int number) {
  const size_t dot = first_file.rfind('.');
  const std::string stem = dot == std::string::npos || dot == 0 ? first_file : first_file.substr(0, dot);
  const std::string extension = stem.size() == first_file.size() ? "" : first_file.substr(stem.size());
  return stem + ".part" + std::to_string(number) + extension;
}

}  // namespace orbed::logger
