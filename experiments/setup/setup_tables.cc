#include "experiments/setup/setup_tables.h"

#include <cmath>
#include <filesystem>
#include <stdexcept>

#include "base/format.h"
#include "base/json_fields.h"
#include "experiments/setup/paper_setup.h"

namespace orbed::study {
namespace {

constexpr size_t kMaxSetups = 100;
constexpr size_t kMaxJoints = 20;

bool IsSetupMode(const std::string& mode) {
  return mode == "ar_reflective" || mode == "ar" || mode == "fixed";
}

// The paper's {mean, median, min, max, std}.
void WritePaperStats(JsonWriter* json, const PaperStats& p) {
  json->BeginObject();
  json->Key("mean").Number(p.mean);
  json->Key("median").Number(p.median);
  json->Key("min").Number(p.min);
  json->Key("max").Number(p.max);
  json->Key("std").Number(p.std);
  json->EndObject();
}

}  // namespace

SetupUserRun ReadSetupResults(const std::string& path) {
  std::string file = path;
  if (std::filesystem::is_directory(path))
    file = (std::filesystem::path(path) / "setup_results.json").string();
  const JsonFields f(file);
  const nlohmann::json doc = f.ReadFile(file, 4 << 20, 8);
  const JsonAt root{doc, ""};
  const std::string status = f.String(f.Member(root, "status"), 16);
  if (status != "ok") {
    const std::string error = f.String(f.Member(root, "error"), 4096);
    throw std::runtime_error(file + ": the set-up run did not finish (status " + EscapeText(status) +
                             (error.empty() ? "" : ": " + EscapeText(error)) + ")");
  }
  SetupUserRun run;
  run.user = f.String(f.Member(root, "user"), 64);
  const JsonAt order = f.Member(root, "order");
  for (size_t i = 0, n = f.ArraySize(order, 3); i < n; ++i)
    run.order.push_back(f.String(f.Element(order, i), 32));
  const JsonAt setups = f.Member(root, "setups");
  size_t num_joints = 0;
  for (size_t i = 0, n = f.ArraySize(setups, kMaxSetups); i < n; ++i) {
    const JsonAt s = f.Element(setups, i);
    SetupRow row;
    row.mode = f.String(f.Member(s, "mode"), 32);
    if (!IsSetupMode(row.mode)) {
      throw std::runtime_error(file + ": " + s.key + ".mode: '" + EscapeText(row.mode) +
                               "' is not one of ar_reflective, ar, fixed");
    }
    row.order = static_cast<int>(f.Integer(f.Member(s, "order"), 1, 3));
    row.target = static_cast<int>(f.Integer(f.Member(s, "target"), 1, 100));
    const JsonAt target = f.Member(s, "target_deg");
    const size_t joints = f.ArraySize(target, kMaxJoints);
    if (joints == 0 || (num_joints != 0 && joints != num_joints)) {
      throw std::runtime_error(file + ": " + target.key + ": " + std::to_string(joints) +
                               " joints, expected " + std::to_string(num_joints ? num_joints : 1) +
                               (num_joints ? "" : " or more"));
    }
    num_joints = joints;
    row.target_deg = f.Numbers(target, joints, -360, 360);
    row.reached_deg = f.Numbers(f.Member(s, "reached_deg"), joints, -360, 360);
    // The design's (absent or null in results written before it).
    if (const std::optional<JsonAt> v = f.OptionalMember(s, "start_id")) row.start_id = f.String(*v, 256);
    if (const std::optional<JsonAt> v = f.OptionalMember(s, "target_id")) row.target_id = f.String(*v, 256);
    if (const std::optional<JsonAt> v = f.OptionalMember(s, "start_deg")) {
      if (f.ArraySize(*v, kMaxJoints) > 0) row.start_deg = f.Numbers(*v, joints, -360, 360);
    }
    for (double t : f.Numbers(f.Member(s, "twisting"), joints, 0, 1)) row.twisting.push_back(t != 0);
    row.execution_s = f.Number(f.Member(s, "execution_s"), 0, 1e6);
    // null (fixed display: no alignment) reads as absent.
    if (const std::optional<JsonAt> alignment = f.OptionalMember(s, "alignment_s")) {
      row.alignment_s = f.Number(*alignment, 0, 1e6);
    }
    if (const std::optional<JsonAt> v = f.OptionalMember(s, "registration")) {
      row.registration = f.String(*v, 16);
      if (row.registration != "measured" && row.registration != "truth")
        throw std::runtime_error(file + ": " + v->key + ": expected measured, truth or null");
    }
    // Beyond the paper: absent or null in results written before orbed-setup recorded them.
    if (const std::optional<JsonAt> v = f.OptionalMember(s, "docking_tip_mm"))
      row.docking_tip_mm = f.Number(*v, 0, 1e5);
    if (const std::optional<JsonAt> v = f.OptionalMember(s, "docking_axis_deg"))
      row.docking_axis_deg = f.Number(*v, 0, 180);
    if (const std::optional<JsonAt> v = f.OptionalMember(s, "min_clearance_m"))
      row.min_clearance_m = f.Number(*v, -10, 1e3);
    if (const std::optional<JsonAt> v = f.OptionalMember(s, "contact")) row.contact = f.Bool(*v);
    if (const std::optional<JsonAt> v = f.OptionalMember(s, "collision_stops"))
      row.collision_stops = static_cast<int>(f.Integer(*v, 0, 1000000));
    run.setups.push_back(std::move(row));
  }
  return run;
}

namespace {
// An id as a CSV cell: the design's ids are words and '/', quoted only if they ever hold a comma or
// a quote.
std::string CsvCell(const std::string& text) {
  if (text.find_first_of(",\"\n") == std::string::npos) return text;
  std::string quoted = "\"";
  for (char c : text) quoted += c == '"' ? std::string("\"\"") : std::string(1, c);
  return quoted + "\"";
}
}  // namespace

std::string SetupJointsCsv(const std::vector<SetupUserRun>& runs) {
  std::string csv =
      "user,mode,order,target,joint,twisting,target_deg,reached_deg,error_deg,start_id,target_id,start_deg\n";
  for (const SetupUserRun& run : runs) {
    for (const SetupRow& row : run.setups) {
      for (size_t j = 0; j < row.target_deg.size(); ++j) {
        csv +=
            run.user + "," + row.mode + "," + std::to_string(row.order) + "," + std::to_string(row.target) +
            "," + std::to_string(j + 1) + "," + std::to_string(row.twisting[j]) + "," +
            JsonNumber(row.target_deg[j]) + "," + JsonNumber(row.reached_deg[j]) + "," +
            JsonNumber(std::abs(row.reached_deg[j] - row.target_deg[j])) + "," + CsvCell(row.start_id) + "," +
            CsvCell(row.target_id) + "," + (row.start_deg.empty() ? "" : JsonNumber(row.start_deg[j])) + "\n";
      }
    }
  }
  return csv;
}

std::string SetupTimesCsv(const std::vector<SetupUserRun>& runs) {
  std::string csv = "user,mode,order,target,execution_s,alignment_s,start_id,target_id\n";
  for (const SetupUserRun& run : runs) {
    for (const SetupRow& row : run.setups) {
      csv += run.user + "," + row.mode + "," + std::to_string(row.order) + "," + std::to_string(row.target) +
             "," + JsonNumber(row.execution_s) + "," + (row.alignment_s ? JsonNumber(*row.alignment_s) : "") +
             "," + CsvCell(row.start_id) + "," + CsvCell(row.target_id) + "\n";
    }
  }
  return csv;
}

std::string SetupDockingCsv(const std::vector<SetupUserRun>& runs) {
  auto cell = [](const std::optional<double>& v) { return v ? JsonNumber(*v) : std::string(); };
  std::string csv =
      "user,mode,order,target,docking_tip_mm,docking_axis_deg,min_clearance_m,contact,collision_stops\n";
  for (const SetupUserRun& run : runs) {
    for (const SetupRow& row : run.setups) {
      csv += run.user + "," + row.mode + "," + std::to_string(row.order) + "," + std::to_string(row.target) +
             "," + cell(row.docking_tip_mm) + "," + cell(row.docking_axis_deg) + "," +
             cell(row.min_clearance_m) + "," + (row.contact ? "1" : "0") + "," +
             std::to_string(row.collision_stops) + "\n";
    }
  }
  return csv;
}

void WriteSetupPaper(JsonWriter* json) {
  json->Key("setup_source").String(kPaperSetupSource);
  json->Key("table2").BeginObject();
  for (int m = 0; m < 3; ++m) {
    json->Key(kSetupModes[m]);
    WritePaperStats(json, kPaperTable2[m]);
  }
  json->EndObject();
  json->Key("table3").BeginObject();
  for (int p = 0; p < 3; ++p) {
    json->Key(kSetupPairs[p]).BeginObject();
    for (int j = 0; j < 6; ++j) json->Key("joint" + std::to_string(j + 1)).Number(kPaperTable3[p][j]);
    json->Key("total").Number(kPaperTable3[p][6]);
    json->EndObject();
  }
  json->EndObject();
  json->Key("table4").BeginObject();
  for (int m = 0; m < 3; ++m) {
    json->Key(kSetupModes[m]).BeginObject();
    json->Key("execution_s");
    WritePaperStats(json, kPaperExecution[m]);
    if (m < 2) {
      json->Key("alignment_s");
      WritePaperStats(json, kPaperAlignment[m]);
    }
    json->EndObject();
  }
  json->EndObject();
}

}  // namespace orbed::study
