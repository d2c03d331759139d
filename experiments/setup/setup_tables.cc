#include "experiments/setup/setup_tables.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <stdexcept>

#include "base/format.h"
#include "base/json_fields.h"
#include "base/random.h"
#include "base/stats.h"
#include "experiments/setup/paper_setup.h"

namespace orbed::study {
namespace {

constexpr size_t kMaxSetups = 100;
constexpr size_t kMaxJoints = 20;

bool IsSetupMode(const std::string& mode) {
  return mode == "ar_reflective" || mode == "ar" || mode == "fixed";
}

// {mean, median, min, max, std[, n]}.
void WriteStats(JsonWriter* json, const Stats5& s, bool with_n = true) {
  json->BeginObject();
  json->Key("mean").Number(s.mean);
  json->Key("median").Number(s.median);
  json->Key("min").Number(s.min);
  json->Key("max").Number(s.max);
  json->Key("std").Number(s.std);
  if (with_n) json->Key("n").Int(s.n);
  json->EndObject();
}

Stats5 FromPaper(const PaperStats& p) { return Stats5{0, p.mean, p.median, p.min, p.max, p.std}; }

void WritePaperStats(JsonWriter* json, const PaperStats& p) { WriteStats(json, FromPaper(p), false); }

bool HasMode(const std::vector<SetupUserRun>& runs, const std::string& mode) {
  for (const SetupUserRun& run : runs) {
    for (const SetupRow& row : run.setups) {
      if (row.mode == mode) return true;
    }
  }
  return false;
}

int NumJoints(const std::vector<SetupUserRun>& runs) {
  for (const SetupUserRun& run : runs) {
    for (const SetupRow& row : run.setups) return static_cast<int>(row.target_deg.size());
  }
  return 0;
}

std::vector<double> Times(const std::vector<SetupUserRun>& runs, const std::string& mode, bool alignment) {
  std::vector<double> out;
  for (const SetupUserRun& run : runs) {
    for (const SetupRow& row : run.setups) {
      if (row.mode != mode) continue;
      if (!alignment) out.push_back(row.execution_s);
      if (alignment && row.alignment_s) out.push_back(*row.alignment_s);
    }
  }
  return out;
}

std::string Clock(double s) {
  const int total = static_cast<int>(std::lround(s));
  char text[16];
  std::snprintf(text, sizeof(text), "%d:%02d", total / 60, total % 60);
  return text;
}

std::string StatsText(const Stats5& s, int decimals, bool clock) {
  auto f = [&](double v) { return clock ? Clock(v) : Fixed(v, decimals); };
  return f(s.mean) + " / " + f(s.median) + " / " + f(s.min) + " / " + f(s.max) + " / " + f(s.std);
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

Stats5 Summarize(const std::vector<double>& values) {
  Stats5 s;
  s.n = static_cast<int>(values.size());
  if (values.empty()) return s;
  s.mean = stats::Mean(values);
  s.median = stats::Median(values);
  s.min = *std::min_element(values.begin(), values.end());
  s.max = *std::max_element(values.begin(), values.end());
  s.std = stats::StdDev(values);
  return s;
}

std::vector<double> JointErrors(const std::vector<SetupUserRun>& runs, const std::string& mode, int joint) {
  std::vector<double> out;
  for (const SetupUserRun& run : runs) {
    for (const SetupRow& row : run.setups) {
      if (row.mode != mode) continue;
      for (size_t j = 0; j < row.target_deg.size(); ++j) {
        if (joint < 0 || static_cast<int>(j) == joint)
          out.push_back(std::abs(row.reached_deg[j] - row.target_deg[j]));
      }
    }
  }
  return out;
}

std::string SetupJointsCsv(const std::vector<SetupUserRun>& runs) {
  std::string csv = "user,mode,order,target,joint,twisting,target_deg,reached_deg,error_deg\n";
  for (const SetupUserRun& run : runs) {
    for (const SetupRow& row : run.setups) {
      for (size_t j = 0; j < row.target_deg.size(); ++j) {
        csv += run.user + "," + row.mode + "," + std::to_string(row.order) + "," +
               std::to_string(row.target) + "," + std::to_string(j + 1) + "," +
               std::to_string(row.twisting[j]) + "," + JsonNumber(row.target_deg[j]) + "," +
               JsonNumber(row.reached_deg[j]) + "," +
               JsonNumber(std::abs(row.reached_deg[j] - row.target_deg[j])) + "\n";
      }
    }
  }
  return csv;
}

std::string SetupTimesCsv(const std::vector<SetupUserRun>& runs) {
  std::string csv = "user,mode,order,target,execution_s,alignment_s\n";
  for (const SetupUserRun& run : runs) {
    for (const SetupRow& row : run.setups) {
      csv += run.user + "," + row.mode + "," + std::to_string(row.order) + "," + std::to_string(row.target) +
             "," + JsonNumber(row.execution_s) + "," + (row.alignment_s ? JsonNumber(*row.alignment_s) : "") +
             "\n";
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

std::vector<PowerPoint> SetupPower(const std::vector<SetupUserRun>& runs, const std::string& a,
                                   const std::string& b, const std::vector<int>& users, int resamples,
                                   double alpha, uint64_t seed) {
  // Each user's pooled errors in a and in b; only users who did both.
  std::vector<std::vector<double>> errors_a, errors_b;
  for (const SetupUserRun& run : runs) {
    std::vector<double> ea = JointErrors({run}, a, -1), eb = JointErrors({run}, b, -1);
    if (ea.empty() || eb.empty()) continue;
    errors_a.push_back(std::move(ea));
    errors_b.push_back(std::move(eb));
  }
  std::vector<PowerPoint> out;
  if (errors_a.empty() || resamples <= 0) return out;
  Random rng(seed);
  const size_t pool = errors_a.size();
  for (int n : users) {
    int rejected = 0;
    for (int k = 0; k < resamples; ++k) {
      std::vector<double> x, y;
      for (int u = 0; u < n; ++u) {
        const size_t pick =
            std::min(pool - 1, static_cast<size_t>(rng.Uniform() * static_cast<double>(pool)));
        x.insert(x.end(), errors_a[pick].begin(), errors_a[pick].end());
        y.insert(y.end(), errors_b[pick].begin(), errors_b[pick].end());
      }
      const stats::MannWhitneyResult r = stats::MannWhitneyU(x, y);
      if (r.valid && r.p_two_sided < alpha) ++rejected;
    }
    out.push_back({n, static_cast<double>(rejected) / resamples});
  }
  return out;
}

namespace {

// The recorded values of an optional per-set-up field over `mode`'s set-ups.
std::vector<double> RowValues(const std::vector<SetupUserRun>& runs, const std::string& mode,
                              std::optional<double> SetupRow::*field) {
  std::vector<double> out;
  for (const SetupUserRun& run : runs) {
    for (const SetupRow& row : run.setups) {
      if (row.mode == mode && row.*field) out.push_back(*(row.*field));
    }
  }
  return out;
}

struct CollisionCounts {
  int setups{0}, contact{0}, stops{0}, near_miss{0};
};
CollisionCounts CountCollisions(const std::vector<SetupUserRun>& runs, const std::string& mode) {
  CollisionCounts c;
  for (const SetupUserRun& run : runs) {
    for (const SetupRow& row : run.setups) {
      if (row.mode != mode) continue;
      ++c.setups;
      c.contact += row.contact;
      c.stops += row.collision_stops;
      c.near_miss += !row.contact && row.min_clearance_m && *row.min_clearance_m < kNearMissM;
    }
  }
  return c;
}

// 1 − truth mean / measured mean, or nothing when either side has no set-up of `mode`.
struct Share {
  Stats5 measured, truth;
  double share{0};
};
std::optional<Share> RegistrationShare(const std::vector<SetupUserRun>& runs,
                                       const std::vector<SetupUserRun>& truth_runs, const std::string& mode) {
  const std::vector<double> measured = JointErrors(runs, mode, -1), truth = JointErrors(truth_runs, mode, -1);
  if (measured.empty() || truth.empty()) return std::nullopt;
  Share s{Summarize(measured), Summarize(truth), 0};
  s.share = s.measured.mean > 0 ? 1 - s.truth.mean / s.measured.mean : 0.0;
  return s;
}

void WriteBeyond(JsonWriter* json, const std::vector<SetupUserRun>& runs,
                 const std::vector<SetupUserRun>& truth_runs) {
  json->Key("beyond").BeginObject();
  json->Key("docking").BeginObject();
  for (const char* mode : kSetupModes) {
    const std::vector<double> tip = RowValues(runs, mode, &SetupRow::docking_tip_mm);
    if (tip.empty()) continue;
    json->Key(mode).BeginObject();
    json->Key("tip_mm");
    WriteStats(json, Summarize(tip));
    json->Key("axis_deg");
    WriteStats(json, Summarize(RowValues(runs, mode, &SetupRow::docking_axis_deg)));
    json->EndObject();
  }
  json->EndObject();
  json->Key("near_miss_m").Number(kNearMissM);
  json->Key("collisions").BeginObject();
  for (const char* mode : kSetupModes) {
    if (!HasMode(runs, mode)) continue;
    const CollisionCounts c = CountCollisions(runs, mode);
    json->Key(mode).BeginObject();
    json->Key("setups").Int(c.setups);
    json->Key("contact").Int(c.contact);
    json->Key("collision_stops").Int(c.stops);
    json->Key("near_miss").Int(c.near_miss);
    const std::vector<double> clearance = RowValues(runs, mode, &SetupRow::min_clearance_m);
    if (!clearance.empty()) {
      json->Key("min_clearance_m");
      WriteStats(json, Summarize(clearance));
    }
    json->EndObject();
  }
  json->EndObject();
  if (!truth_runs.empty()) {
    json->Key("registration_share").BeginObject();
    for (const char* mode : kSetupModes) {
      const std::optional<Share> share = RegistrationShare(runs, truth_runs, mode);
      if (!share) continue;
      json->Key(mode).BeginObject();
      json->Key("measured_deg");
      WriteStats(json, share->measured);
      json->Key("truth_deg");
      WriteStats(json, share->truth);
      json->Key("share").Number(share->share);
      json->EndObject();
    }
    json->EndObject();
  }
  json->Key("power_method")
      .String(
          "bootstrap over users: 500 studies of N users drawn with replacement per N, Table 3's pooled "
          "two-sided Mann-Whitney U on all joints, power = fraction with p < 0.05");
  json->Key("power").BeginObject();
  for (const char* pair : kSetupPairs) {
    const std::string p = pair;
    const std::vector<PowerPoint> curve =
        SetupPower(runs, p.substr(0, p.find('/')), p.substr(p.find('/') + 1), kPowerUsers, 500, 0.05, 1);
    if (curve.empty()) continue;
    json->Key(p).BeginObject();
    json->Key("users").BeginArray();
    for (const PowerPoint& point : curve) json->Int(point.users);
    json->EndArray();
    json->Key("power").BeginArray();
    for (const PowerPoint& point : curve) json->Number(point.power);
    json->EndArray();
    json->Key("users_for_80");
    const auto enough =
        std::find_if(curve.begin(), curve.end(), [](const PowerPoint& q) { return q.power >= 0.8; });
    if (enough != curve.end()) {
      json->Int(enough->users);
    } else {
      json->Null();
    }
    json->EndObject();
  }
  json->EndObject();
  json->EndObject();
}

}  // namespace

void WriteSetupTables(JsonWriter* json, const std::vector<SetupUserRun>& runs,
                      const std::vector<SetupUserRun>& truth_runs) {
  json->Key("setup_users").Int(static_cast<int64_t>(runs.size()));
  json->Key("table2").BeginObject();
  for (const char* mode : kSetupModes) {
    if (!HasMode(runs, mode)) continue;
    json->Key(mode);
    WriteStats(json, Summarize(JointErrors(runs, mode, -1)));
  }
  json->EndObject();
  json->Key("table3").BeginObject();
  const int joints = NumJoints(runs);
  for (const char* pair : kSetupPairs) {
    const std::string p = pair;
    const std::string a = p.substr(0, p.find('/')), b = p.substr(p.find('/') + 1);
    if (!HasMode(runs, a) || !HasMode(runs, b)) continue;
    json->Key(p).BeginObject();
    for (int j = -1; j < joints; ++j) {
      const stats::MannWhitneyResult r =
          stats::MannWhitneyU(JointErrors(runs, a, j), JointErrors(runs, b, j));
      json->Key(j < 0 ? "total" : "joint" + std::to_string(j + 1));
      if (r.valid) {
        json->Number(r.p_two_sided);
      } else {
        json->Null();  // all tied (or empty): no test
      }
    }
    json->EndObject();
  }
  json->EndObject();
  json->Key("table3_test").String("mann_whitney_u");
  json->Key("table4").BeginObject();
  for (const char* mode : kSetupModes) {
    if (!HasMode(runs, mode)) continue;
    json->Key(mode).BeginObject();
    json->Key("execution_s");
    WriteStats(json, Summarize(Times(runs, mode, false)));
    const std::vector<double> alignment = Times(runs, mode, true);
    if (!alignment.empty()) {
      json->Key("alignment_s");
      WriteStats(json, Summarize(alignment));
    }
    json->EndObject();
  }
  json->EndObject();
  WriteBeyond(json, runs, truth_runs);
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

std::string SetupSummary(const std::vector<SetupUserRun>& runs, const std::vector<SetupUserRun>& truth_runs) {
  size_t setups = 0;
  for (const SetupUserRun& run : runs) setups += run.setups.size();
  std::string text = "Robot set-up study: " + std::to_string(runs.size()) + " users, " +
                     std::to_string(setups) +
                     " set-ups\n  Table 2, joint error [deg]   mean / median / min / max / std\n";
  for (int m = 0; m < 3; ++m) {
    if (!HasMode(runs, kSetupModes[m])) continue;
    const PaperStats& p = kPaperTable2[m];
    text += "    " + std::string(kSetupModes[m]) + std::string(15 - std::string(kSetupModes[m]).size(), ' ') +
            StatsText(Summarize(JointErrors(runs, kSetupModes[m], -1)), 1, false) + "   paper " +
            StatsText(FromPaper(p), 2, false) + "\n";
  }
  text += "  Table 4, execution time [min:s]\n";
  for (int m = 0; m < 3; ++m) {
    if (!HasMode(runs, kSetupModes[m])) continue;
    const PaperStats& p = kPaperExecution[m];
    text += "    " + std::string(kSetupModes[m]) + std::string(15 - std::string(kSetupModes[m]).size(), ' ') +
            StatsText(Summarize(Times(runs, kSetupModes[m], false)), 0, true) + "   paper " +
            StatsText(FromPaper(p), 0, true) + "\n";
  }
  text +=
      "  Beyond the paper: docking error at the trocar (tip [mm] / tool axis [deg], median), contacts, "
      "collision stops, near misses (< " +
      Fixed(kNearMissM * 100, 0) + " cm)\n";
  for (int m = 0; m < 3; ++m) {
    const std::string mode = kSetupModes[m];
    if (!HasMode(runs, mode)) continue;
    const std::vector<double> tip = RowValues(runs, mode, &SetupRow::docking_tip_mm),
                              axis = RowValues(runs, mode, &SetupRow::docking_axis_deg);
    const CollisionCounts c = CountCollisions(runs, mode);
    text += "    " + mode + std::string(15 - mode.size(), ' ') +
            (tip.empty() ? std::string("(not recorded)")
                         : Fixed(stats::Median(tip), 0) + " mm / " + Fixed(stats::Median(axis), 1) + " deg") +
            ", " + std::to_string(c.contact) + " contact(s), " + std::to_string(c.stops) + " stop(s), " +
            std::to_string(c.near_miss) + " near miss(es)\n";
  }
  for (const char* mode : kSetupModes) {
    const std::optional<Share> share = RegistrationShare(runs, truth_runs, mode);
    if (!share) continue;
    text += "  Registration's share, " + std::string(mode) + ": mean joint error " +
            Fixed(share->measured.mean, 1) + " deg measured, " + Fixed(share->truth.mean, 1) +
            " deg with the true registration (" + Fixed(100 * share->share, 0) + " %)\n";
  }
  const std::vector<PowerPoint> power = SetupPower(runs, "ar_reflective", "ar", kPowerUsers, 500, 0.05, 1);
  if (!power.empty()) {
    text += "  Power of ar_reflective vs ar (Table 3 total, alpha 0.05), users: power\n   ";
    for (const PowerPoint& q : power) text += " " + std::to_string(q.users) + ": " + Fixed(q.power, 2);
    text += "\n";
  }
  return text;
}

}  // namespace orbed::study
