#include "procs/logger/log_tool.h"

#include <algorithm>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <map>
#include <regex>
#include <string>

#include <CLI/CLI.hpp>

#include "base/command_line.h"
#include "base/format.h"
#include "procs/logger/csv_export.h"
#include "procs/logger/event_log_reader.h"
#include "procs/logger/event_log_writer.h"
#include "procs/logger/mcap_export.h"
#include "sim/foxglove_messages.h"

namespace orbed::logger {
namespace {

struct ChannelSummary {
  int64_t events = 0;
  uint64_t bytes = 0;
  int64_t first_us = 0, last_us = 0;
  double largest_gap_s = 0;
};

struct LogSummary {
  std::map<std::string, ChannelSummary> channels;
  int64_t events = 0;
  int64_t first_us = 0, last_us = 0;
  std::vector<LogDamage> damage;
};

LogSummary Summarize(const MappedLog& log) {
  LogSummary s;
  EventLogScanner scanner = log.Scanner();
  LogEvent e;
  while (scanner.Next(&e)) {
    ChannelSummary& c = s.channels[e.channel];
    if (c.events > 0) c.largest_gap_s = std::max(c.largest_gap_s, (e.timestamp_us - c.last_us) * 1e-6);
    if (c.events == 0) c.first_us = e.timestamp_us;
    c.last_us = e.timestamp_us;
    ++c.events;
    c.bytes += e.size;
    if (s.events == 0) s.first_us = e.timestamp_us;
    s.first_us = std::min(s.first_us, e.timestamp_us);
    s.last_us = std::max(s.last_us, e.timestamp_us);
    ++s.events;
  }
  s.damage = scanner.damage();
  return s;
}

std::string Damage(const LogDamage& d) {
  return "bytes " + std::to_string(d.offset) + ".." + std::to_string(d.offset + d.bytes) + " (" +
         std::to_string(d.bytes) + " bytes): " + EscapeText(d.reason);
}

int Info(const MappedLog& log, const std::string& path, std::ostream& out) {
  const LogSummary s = Summarize(log);
  const double duration_s = s.events > 1 ? (s.last_us - s.first_us) * 1e-6 : 0.0;
  out << EscapeText(path) << ": " << s.events << " events, " << log.size() << " bytes, "
      << Fixed(duration_s, 3) << " s, " << s.channels.size() << " channels, " << s.damage.size()
      << " damaged range(s)\n";
  char line[512];
  std::snprintf(line, sizeof(line), "%-28s %10s %12s %9s %11s\n", "channel", "events", "bytes", "rate_hz",
                "max_gap_s");
  out << line;
  for (const auto& [name, c] : s.channels) {
    const double span_s = (c.last_us - c.first_us) * 1e-6;
    const double rate_hz = c.events > 1 && span_s > 0 ? (c.events - 1) / span_s : 0.0;
    std::snprintf(line, sizeof(line), "%-28s %10lld %12llu %9.1f %11.3f\n", EscapeText(name).c_str(),
                  static_cast<long long>(c.events), static_cast<unsigned long long>(c.bytes), rate_hz,
                  c.largest_gap_s);
    out << line;
  }
  for (const LogDamage& d : s.damage) out << "damaged: " << Damage(d) << "\n";
  return 0;
}

int Check(const MappedLog& log, const std::string& path, std::ostream& out) {
  const LogSummary s = Summarize(log);
  for (const LogDamage& d : s.damage) out << EscapeText(path) << ": damaged " << Damage(d) << "\n";
  uint64_t damaged = 0;
  for (const LogDamage& d : s.damage) damaged += d.bytes;
  out << EscapeText(path) << ": " << s.events << " events read, " << damaged << " of " << log.size()
      << " bytes damaged in " << s.damage.size() << " range(s)\n";
  return s.damage.empty() ? 0 : 1;
}

int Cut(const MappedLog& log, const std::string& out_path, double from_s, double to_s,
        const std::regex& channels, std::ostream& out, std::ostream& err) {
  EventLogWriter writer(out_path);
  if (!writer.ok()) {
    err << "orbed-log: " << writer.error() << "\n";
    return 1;
  }
  EventLogScanner scanner = log.Scanner();
  LogEvent e;
  EventWindow window(from_s, to_s, channels);
  int64_t kept = 0;
  while (scanner.Next(&e)) {
    if (!window.Take(e)) continue;
    if (writer.Write(e.timestamp_us, e.channel, e.data, e.size) == 0) {
      err << "orbed-log: " << writer.error() << "\n";
      return 1;
    }
    ++kept;
  }
  writer.Close();
  if (!writer.error().empty()) {
    err << "orbed-log: " << writer.error() << "\n";
    return 1;
  }
  out << "orbed-log: " << kept << " events written to " << EscapeText(out_path) << "\n";
  return 0;
}

int Export(const MappedLog& log, const CsvExportOptions& options, std::ostream& out, std::ostream& err) {
  const CsvExportResult result = ExportCsv(log, options);
  if (!result.ok()) {
    err << "orbed-log: " << EscapeText(result.error) << "\n";
    return 1;
  }
  char line[512];
  std::snprintf(line, sizeof(line), "%-28s %-24s %10s %8s %9s  %s\n", "channel", "type", "rows", "columns",
                "refused", "file");
  out << line;
  int files = 0;
  for (const CsvChannelResult& c : result.channels) {
    int64_t refused = 0;
    for (const auto& [reason, n] : c.refused) refused += n;
    if (c.file.empty()) {
      out << EscapeText(c.channel) << ": not exported, no orbed or Drake fingerprint (" << c.unknown
          << " events)\n";
      continue;
    }
    ++files;
    std::snprintf(line, sizeof(line), "%-28s %-24s %10lld %8zu %9lld  %s\n", EscapeText(c.channel).c_str(),
                  c.type.c_str(), static_cast<long long>(c.rows), c.columns + 1,
                  static_cast<long long>(refused + c.unknown), EscapeText(c.file).c_str());
    out << line;
    for (const auto& [reason, n] : c.refused) out << "  refused " << n << ": " << reason << "\n";
    if (c.unknown > 0) out << "  refused " << c.unknown << ": unknown fingerprint\n";
  }
  out << "orbed-log: " << files << " CSV file(s) in " << EscapeText(options.out_dir) << "\n";
  return 0;
}

int ExportMcapFile(const MappedLog& log, const McapExportOptions& options, std::ostream& out,
                   std::ostream& err) {
  const McapExportResult result = ExportMcap(log, options);
  if (!result.ok()) {
    err << "orbed-log: " << EscapeText(result.error) << "\n";
    return 1;
  }
  char line[512];
  std::snprintf(line, sizeof(line), "%-28s %-24s %10s %9s\n", "channel / topic", "type", "messages",
                "refused");
  out << line;
  int64_t total = 0;
  for (const McapChannelResult& c : result.channels) {
    int64_t refused = c.unknown;
    for (const auto& [reason, n] : c.refused) refused += n;
    total += c.messages;
    std::snprintf(line, sizeof(line), "%-28s %-24s %10lld %9lld\n", EscapeText(c.channel).c_str(),
                  c.type.empty() ? "(none known)" : c.type.c_str(), static_cast<long long>(c.messages),
                  static_cast<long long>(refused));
    out << line;
    for (const auto& [reason, n] : c.refused) out << "  refused " << n << ": " << reason << "\n";
    if (c.unknown > 0) out << "  refused " << c.unknown << ": unknown fingerprint (not exported)\n";
  }
  for (const auto& [topic, n] : result.topics) {
    total += n;
    std::string schema;
    for (const foxglove::ChannelSpec& spec : foxglove::Channels())
      if (spec.topic == topic) schema = spec.schema_name;
    std::snprintf(line, sizeof(line), "%-28s %-24s %10lld %9s\n", topic.c_str(), schema.c_str(),
                  static_cast<long long>(n), "");
    out << line;
  }
  if (result.events_on_channels_left_out > 0)
    out << "left out: " << result.events_on_channels_left_out << " events on channels beyond the first "
        << kMaxMcapChannels << "\n";
  if (!options.provenance_path.empty())
    out << "provenance: " << EscapeText(options.provenance_path)
        << (result.provenance ? " (metadata \"provenance\")" : " left out: " + result.provenance_problem)
        << "\n";
  out << "orbed-log: " << total << " messages on " << result.channels.size() + result.topics.size()
      << " channels in " << EscapeText(options.out_path) << " (MCAP, chunked and indexed)\n";
  return 0;
}

}  // namespace

int RunLogTool(int argc, const char* const* argv, std::ostream& out, std::ostream& err) {
  CLI::App app{
      "orbed-log: what is in an LCM event log (orbed-logger's or lcm-logger's), whether it is damaged,\n"
      "a cut of it by time and channel, and its messages as CSV tables or as an MCAP file for Foxglove."};
  AddVersionFlag(&app);
  app.require_subcommand(1);
  std::string log_path, out_path, channels = ".*";
  double from_s = 0, to_s = 1e18;
  auto* info = app.add_subcommand("info", "channels, counts, bytes, rates, largest gaps, duration, damage");
  info->add_option("log", log_path, "the log")->required();
  auto* check = app.add_subcommand("check", "damaged byte ranges (exit 1 if any); the rest is still read");
  check->add_option("log", log_path, "the log")->required();
  auto* cut = app.add_subcommand("cut", "events in a time range and on matching channels, as a new log");
  cut->add_option("log", log_path, "the log")->required();
  cut->add_option("out", out_path, "the new log (overwritten)")->required();
  cut->add_option("--from-s", from_s, "from this many seconds after the first event")
      ->check(orbed::NonNegativeNumber());
  cut->add_option("--to-s", to_s, "to this many seconds after the first event")
      ->check(orbed::NonNegativeNumber());
  cut->add_option("--channels", channels, "keep channels whose whole name matches this regex")
      ->capture_default_str();
  auto* export_cmd = app.add_subcommand(
      "export",
      "CSV: one file per channel, every field a column named by its path with its unit; MCAP: one file "
      "for Foxglove");
  export_cmd->add_option("log", log_path, "the log")->required();
  export_cmd
      ->add_option("out", out_path,
                   "the folder for the CSV files (created; files overwritten), or the MCAP file")
      ->required();
  bool csv = false, mcap = false;
  std::string urdf_path, scene_path;
  auto* csv_flag =
      export_cmd->add_flag("--csv", csv, "one CSV file per channel into the folder OUT (the default)");
  export_cmd
      ->add_flag("--mcap", mcap, "one MCAP file OUT for Foxglove: its channels and every LCM channel as JSON")
      ->excludes(csv_flag);
  export_cmd->add_option("--urdf", urdf_path,
                         "--mcap: the robot of /scene and /tf (default: the shipped iiwa 7)");
  export_cmd->add_option(
      "--scene", scene_path,
      "--mcap: the scene of /scene (default: the run's, from provenance.json beside the log, else "
      "the shipped OR; none: no scene)");
  export_cmd->add_option("--from-s", from_s, "from this many seconds after the first event")
      ->check(orbed::NonNegativeNumber());
  export_cmd->add_option("--to-s", to_s, "to this many seconds after the first event")
      ->check(orbed::NonNegativeNumber());
  export_cmd->add_option("--channels", channels, "export channels whose whole name matches this regex")
      ->capture_default_str();
  if (const auto code = ParseArguments(&app, argc, argv, out, err)) return *code;
  std::regex channel_regex;
  try {
    channel_regex = std::regex(channels, std::regex::extended);
  } catch (const std::regex_error& e) {
    err << "orbed-log: --channels '" << EscapeText(channels) << "' is not a regular expression\n";
    return 2;
  }
  if ((*cut || *export_cmd) && to_s < from_s) {
    err << "orbed-log: --to-s is before --from-s\n";
    return 2;
  }
  const MappedLog log(log_path);
  if (!log.ok()) {
    err << "orbed-log: " << log.error() << "\n";
    return 1;
  }
  LogEvent first;
  if (log.size() > 0 && !log.Scanner().Next(&first)) {  // empty is a log nothing was written to yet
    err << "orbed-log: " << EscapeText(log_path)
        << " is not an LCM event log (not one event in it; an event starts with the sync word 0xEDA1DA01)\n";
    return 1;
  }
  try {
    if (*info) return Info(log, log_path, out);
    if (*check) return Check(log, log_path, out);
    if (*export_cmd && mcap) {
      McapExportOptions options;
      options.out_path = out_path;
      options.from_s = from_s;
      options.to_s = to_s;
      options.channels = channel_regex;
      options.urdf_path = urdf_path;
      options.scene_path = scene_path;
      options.log_name = std::filesystem::path(log_path).filename().string();
      const std::filesystem::path provenance =
          std::filesystem::path(log_path).parent_path() / "provenance.json";
      if (std::filesystem::is_regular_file(provenance)) options.provenance_path = provenance.string();
      return ExportMcapFile(log, options, out, err);
    }
    if (*export_cmd) {
      CsvExportOptions options;
      options.out_dir = out_path;
      options.from_s = from_s;
      options.to_s = to_s;
      options.channels = channel_regex;
      return Export(log, options, out, err);
    }
    return Cut(log, out_path, from_s, to_s, channel_regex, out, err);
  } catch (const std::exception& e) {
    err << "orbed-log: " << e.what() << "\n";
    return 1;
  }
}

}  // namespace orbed::logger
