#pragma once
/// @file
/// `orbed-log` (thin main in log_tool_main.cc): reads any LCM event log (orbed-logger's or LCM's own
/// lcm-logger's) with the damage-tolerant scanner (event_log_reader.h), as a library so tests run it
/// in-process.
///
///   orbed-log info LOG     channels with their event counts, bytes, rates [Hz] and largest gap
///                          between two events [s]; the log's duration; damaged byte ranges
///   orbed-log check LOG    every damaged range with its byte offset and what was there; exit 1 when
///                          there is any (the events around it are still read: resync on the sync word)
///   orbed-log cut LOG OUT [--from-s A] [--to-s B] [--channels REGEX]
///                          the events from A to B seconds after the log's first event whose
///                          channel matches REGEX (whole name), written as a new log (numbered from 0,
///                          timestamps kept); damage is left behind
///   orbed-log export LOG DIR [--csv] [--from-s A] [--to-s B] [--channels REGEX]
///                          one CSV file per channel of a known type (csv_export.h): a column per
///                          field, named by its path with its unit; refusals counted per reason
///   orbed-log export LOG OUT.mcap --mcap [--from-s A] [--to-s B] [--channels REGEX] [--urdf F] [--scene F]
///                          one MCAP file for Foxglove (mcap_export.h): the Foxglove bridge's channels
///                          and every LCM channel of a known type as JSON, the provenance.json beside
///                          the log as metadata
///
/// Exit codes: 0 ok; 1 check found damage, or a log, a CSV or an MCAP file cannot be read or written (one
/// line on stderr); 2 bad arguments. Threading: single-threaded.

#include <ostream>

namespace orbed::logger {

int RunLogTool(int argc, const char* const* argv, std::ostream& out, std::ostream& err);

}  // namespace orbed::logger
