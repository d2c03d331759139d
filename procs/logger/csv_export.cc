#include "procs/logger/csv_export.h"

#include <cctype>
#include <filesystem>
#include <fstream>
#include <memory>
#include <set>
#include <unordered_map>

#include <orbed/all_types.hpp>
#include <orbed/flatten.hpp>

#include "lcmtypes/bounded_decode.h"

namespace orbed::logger {
namespace {

// One message type: its fingerprint, name and how to decode and flatten it.
struct MessageType {
  int64_t fingerprint;
  const char* name;
  // Decodes (DecodeBounded) and flattens into *row; on refusal, the reason's class name.
  bool (*flatten)(const uint8_t* data, size_t size, flat::FlatRow* row, std::string* reason);
};

template <class Msg>
bool FlattenAs(const uint8_t* data, size_t size, flat::FlatRow* row, std::string* reason) {
  Msg msg;
  const DecodeResult decoded = DecodeBounded(data, size, &msg);
  if (!decoded.ok()) {
    *reason = wire::KindName(decoded.kind);
    return false;
  }
  row->Clear();
  flat::Flatten(msg, "", *row);
  return true;
}

const std::vector<MessageType>& MessageTypes() {
#define ORBED_MESSAGE_TYPE(T) {orbed::T::getHash(), #T, &FlattenAs<orbed::T>},
  static const std::vector<MessageType> types = {ORBED_FOR_EACH_LCM_TYPE(ORBED_MESSAGE_TYPE)};
#undef ORBED_MESSAGE_TYPE
  return types;
}

const MessageType* TypeOf(const uint8_t* data, size_t size) {
  return FindTypeByFingerprint(MessageTypes(), data, size);
}

// One message type on one channel: its columns in order, its rows and refusals, and (pass 2) the
// slots of the previous row's names.
struct TypeColumns {
  int first_seen = 0;  // order among the channel's types
  int64_t rows = 0;
  std::map<std::string, int64_t> refused;
  std::vector<std::string> columns;
  std::unordered_map<std::string, size_t> column_of;
  std::vector<std::string> last_names;
  std::vector<size_t> last_slots;
};

// A channel during the export: the types seen on it, the one chosen (the most rows; the first seen
// on a tie) and its file.
struct ChannelState {
  CsvChannelResult result;
  std::map<const MessageType*, TypeColumns> types;
  const MessageType* chosen = nullptr;
  std::unique_ptr<std::ofstream> file;
};

// Adds the names not yet known, each right after the known name that precedes it in `names`, so
// that an array's longer messages put their extra elements after its shorter ones' last.
void MergeColumns(const std::vector<std::string>& names, TypeColumns* c) {
  if (names == c->last_names) return;
  size_t insert_at = 0;
  for (const std::string& name : names) {
    const auto it = c->column_of.find(name);
    if (it != c->column_of.end()) {
      insert_at = it->second + 1;
      continue;
    }
    c->columns.insert(c->columns.begin() + static_cast<std::ptrdiff_t>(insert_at), name);
    for (size_t k = insert_at; k < c->columns.size(); ++k) c->column_of[c->columns[k]] = k;
    ++insert_at;
  }
  c->last_names = names;
}

// Calls visit(event, channel, type, row) for every event in the time range on a matching channel
// that decodes as the type its fingerprint names, and refused(channel, type, reason) for the others
// (type null: no known fingerprint).
template <class Visit, class Refused>
void ForEachMessage(const MappedLog& log, const CsvExportOptions& options,
                    std::map<std::string, ChannelState>* channels, Visit visit, Refused refused) {
  EventLogScanner scanner = log.Scanner();
  LogEvent e;
  EventWindow window(options.from_s, options.to_s, options.channels);
  flat::FlatRow row;
  std::string reason;
  while (scanner.Next(&e)) {
    if (!window.Take(e)) continue;
    ChannelState& c = (*channels)[e.channel];
    if (c.result.channel.empty()) c.result.channel = e.channel;
    const MessageType* type = TypeOf(e.data, e.size);
    if (type == nullptr) {
      refused(c, nullptr, "unknown fingerprint");
    } else if (type->flatten(e.data, e.size, &row, &reason)) {
      visit(e, c, type, row);
    } else {
      refused(c, type, reason);
    }
  }
}

std::string CsvLine(const std::vector<std::string>& cells) {
  std::string line;
  for (size_t k = 0; k < cells.size(); ++k) {
    if (k > 0) line += ',';
    line += cells[k];
  }
  return line + '\n';
}

}  // namespace

std::string CsvFileStem(const std::string& channel) {
  std::string stem;
  for (unsigned char ch : channel) {
    const bool keep = std::isalnum(ch) || ch == '_' || ch == '-' || ch == '.';
    stem += keep && ch < 0x80 ? static_cast<char>(ch) : '_';
  }
  if (stem.empty() || stem.find_first_not_of('.') == std::string::npos) stem = "_" + stem;
  return stem;
}

CsvExportResult ExportCsv(const MappedLog& log, const CsvExportOptions& options) {
  CsvExportResult out;
  std::map<std::string, ChannelState> channels;
  // Pass 1: the types on each channel, their columns, the counts.
  const auto type_columns = [](ChannelState& c, const MessageType* type) -> TypeColumns& {
    const auto [it, added] = c.types.try_emplace(type);
    if (added) it->second.first_seen = static_cast<int>(c.types.size());
    return it->second;
  };
  ForEachMessage(
      log, options, &channels,
      [&](const LogEvent&, ChannelState& c, const MessageType* type, const flat::FlatRow& row) {
        TypeColumns& t = type_columns(c, type);
        MergeColumns(row.names, &t);
        ++t.rows;
      },
      [&](ChannelState& c, const MessageType* type, const std::string& reason) {
        if (type == nullptr) {
          ++c.result.unknown;
        } else {
          ++type_columns(c, type).refused[reason];
        }
      });
  size_t exported = 0;
  for (auto& [name, c] : channels) {
    for (const auto& [type, t] : c.types) {
      const TypeColumns* best = c.chosen ? &c.types.at(c.chosen) : nullptr;
      if (!best || t.rows > best->rows || (t.rows == best->rows && t.first_seen < best->first_seen))
        c.chosen = type;
    }
    if (!c.chosen) continue;
    ++exported;
    const TypeColumns& t = c.types.at(c.chosen);
    c.result.type = c.chosen->name;
    c.result.rows = t.rows;
    c.result.columns = t.columns.size();
    c.result.refused = t.refused;
    for (const auto& [type, other] : c.types) {
      if (type == c.chosen) continue;
      int64_t n = other.rows;
      for (const auto& [reason, k] : other.refused) n += k;
      c.result.refused[std::string("another type (") + type->name + ")"] += n;
    }
  }
  if (exported > kMaxCsvChannels) {
    out.error = std::to_string(exported) + " channels to export, more than " +
                std::to_string(kMaxCsvChannels) + " files at once: choose some with --channels";
    return out;
  }
  std::error_code ec;
  std::filesystem::create_directories(options.out_dir, ec);
  if (ec) {
    out.error = "cannot create " + options.out_dir + ": " + ec.message();
    return out;
  }
  // The files, with their header rows.
  std::set<std::string> stems;
  for (auto& [name, c] : channels) {
    if (!c.chosen) continue;
    TypeColumns& t = c.types.at(c.chosen);
    std::string stem = CsvFileStem(name);
    for (int k = 2; !stems.insert(stem).second; ++k) stem = CsvFileStem(name) + "_" + std::to_string(k);
    c.result.file = (std::filesystem::path(options.out_dir) / (stem + ".csv")).string();
    c.file = std::make_unique<std::ofstream>(c.result.file, std::ios::binary | std::ios::trunc);
    std::vector<std::string> header = {"log_utime (us)"};
    for (const std::string& column : t.columns) header.push_back(flat::CsvCell(column));
    *c.file << CsvLine(header);
    if (!*c.file) {
      out.error = "cannot write " + c.result.file;
      return out;
    }
    t.last_names.clear();
  }
  // Pass 2: the rows of each channel's chosen type.
  std::vector<std::string> cells;
  ForEachMessage(
      log, options, &channels,
      [&cells](const LogEvent& e, ChannelState& c, const MessageType* type, const flat::FlatRow& row) {
        if (type != c.chosen) return;
        TypeColumns& t = c.types.at(type);
        if (row.names != t.last_names) {
          t.last_slots.clear();
          for (const std::string& name : row.names) t.last_slots.push_back(t.column_of.at(name));
          t.last_names = row.names;
        }
        cells.assign(t.columns.size() + 1, std::string());
        cells[0] = std::to_string(e.timestamp_us);
        for (size_t k = 0; k < row.cells.size(); ++k) cells[t.last_slots[k] + 1] = row.cells[k];
        *c.file << CsvLine(cells);
      },
      [](ChannelState&, const MessageType*, const std::string&) {});
  for (auto& [name, c] : channels) {
    if (c.file) {
      c.file->close();
      if (!*c.file && out.error.empty()) out.error = "cannot write " + c.result.file;
    }
    out.channels.push_back(c.result);
  }
  return out;
}

}  // namespace orbed::logger
