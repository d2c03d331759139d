#pragma once
/// @file
/// `orbed-log export --csv`: an LCM event log as one CSV file per channel, every message flattened
/// into columns named by field path with units (lcmtypes/flat_row.h, generated orbed/flatten.hpp).
///
/// A channel's type is recognised by the 8-byte fingerprint its messages start with: every orbed
/// type, which includes Drake's lcmt_iiwa_status/command and lcmt_viewer_* (same fingerprints).
/// Each message goes through DecodeBounded as the type its fingerprint names; one that does not
/// decode (a bad count, truncated, ...) becomes no row and is counted under its reason. A channel's
/// type is the one with the most decoded messages on it (the first seen on a tie); messages of other
/// types there are counted as "another type (name)". Channels with no known fingerprint are listed and
/// skipped. Arrays whose length varies get as many columns as their longest message needs, in field
/// order; shorter messages leave those cells empty.
///
/// File per channel: DIR/<channel>.csv, the channel name with every byte outside [A-Za-z0-9_.-]
/// replaced by '_' (and a numbered suffix if two names meet). First column "log_utime (us)": the
/// event's log timestamp [us since the Unix epoch]. Two passes over the log (column layout, then
/// rows); memory O(columns), not O(events).
///
/// Threading: single-threaded.

#include <cstdint>
#include <map>
#include <ostream>
#include <regex>
#include <string>
#include <vector>

#include "procs/logger/event_log_reader.h"

namespace orbed::logger {

struct CsvExportOptions {
  std::string out_dir;             ///< created if missing; files in it are overwritten
  double from_s = 0, to_s = 1e18;  ///< seconds after the log's first event
  std::regex channels{".*"};       ///< whole channel name must match
};

/// More channels than this in one export are refused (each is an open file): cut with --channels.
constexpr size_t kMaxCsvChannels = 500;

struct CsvChannelResult {
  std::string channel, type, file;  ///< file empty when the channel had no known type
  int64_t rows = 0;
  size_t columns = 0;
  int64_t unknown = 0;                     ///< events with no known fingerprint
  std::map<std::string, int64_t> refused;  ///< reason → events that did not decode as `type`
};

struct CsvExportResult {
  std::vector<CsvChannelResult> channels;  ///< in name order
  std::string error;                       ///< set when the export could not be written
  bool ok() const { return error.empty(); }
};

/// Writes the CSV files of `log` into options.out_dir.
CsvExportResult ExportCsv(const MappedLog& log, const CsvExportOptions& options);

/// A channel name as a file name stem ([A-Za-z0-9_.-] kept, other bytes '_', never "." or "..").
std::string CsvFileStem(const std::string& channel);

}  // namespace orbed::logger
