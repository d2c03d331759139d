#include "experiments/viraal/results.h"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "base/format.h"
#include "base/json.h"
#include "base/json_fields.h"
#include "base/replace_file.h"
#include "base/stats.h"
#include "experiments/viraal/paper_reference.h"
#include "lcmtypes/contract/session_control.h"

namespace orbed::viraal {
namespace {

std::vector<double> Numbers(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }

void WriteTable1(JsonWriter* json, const Table1Row& row) {
  json->BeginObject();
  json->Key("num_trials").Int(row.num_trials);
  json->Key("axes_mean_mm").Array(Numbers(row.axes_mean_mm));
  json->Key("axes_std_mm").Array(Numbers(row.axes_std_mm));
  json->Key("mean_mm").Number(row.mean_mm);
  json->Key("std_mm").Number(row.std_mm);
  json->EndObject();
}

void WritePose(JsonWriter* json, const Eigen::Isometry3d& X) {
  const Eigen::Quaterniond q(X.linear());
  // w >= 0, as ToPose does, so equal rotations print equally.
  const double s = q.w() < 0 ? -1.0 : 1.0;
  json->BeginObject();
  json->Key("position_m")
      .Array(std::vector<double>{X.translation().x(), X.translation().y(), X.translation().z()});
  json->Key("quaternion_wxyz").Array(std::vector<double>{s * q.w(), s * q.x(), s * q.y(), s * q.z()});
  json->EndObject();
}

void WriteMeasures(JsonWriter* json, const ErrorMeasures& e) {
  json->Key("translation_error_mm").Number(e.translation_error_mm);
  json->Key("rotation_error_deg").Number(e.rotation_error_deg);
  json->Key("misalignment_mm").Number(e.misalignment_mm);
  json->Key("base_translation_error_mm").Number(e.base_translation_error_mm);
  json->Key("flange_translation_error_mm").Number(e.flange_translation_error_mm);
  json->Key("misalignment_axes_mm")
      .Array(std::vector<double>{e.misalignment_axes_mm.x(), e.misalignment_axes_mm.y(),
                                 e.misalignment_axes_mm.z()});
  json->Key("misalignment_mean_pair_distance_mm").Number(e.misalignment_mean_pair_distance_mm);
  if (e.viewer_axes_mm) json->Key("viewer_axes_mm").Array(Numbers(*e.viewer_axes_mm));
  json->Key("landmarks").String(e.landmarks);
  json->Key("truth_misalignment_mm").Number(e.truth_misalignment_mm);
}

// The measures that get trial statistics, by name.
const std::vector<std::pair<std::string, std::function<double(const ErrorMeasures&)>>>& StatMeasures() {
  static const std::vector<std::pair<std::string, std::function<double(const ErrorMeasures&)>>> measures = {
      {"translation_error_mm", [](const ErrorMeasures& e) { return e.translation_error_mm; }},
      {"rotation_error_deg", [](const ErrorMeasures& e) { return e.rotation_error_deg; }},
      {"misalignment_mm", [](const ErrorMeasures& e) { return e.misalignment_mm; }},
      {"truth_misalignment_mm", [](const ErrorMeasures& e) { return e.truth_misalignment_mm; }},
      {"base_translation_error_mm", [](const ErrorMeasures& e) { return e.base_translation_error_mm; }},
      {"flange_translation_error_mm", [](const ErrorMeasures& e) { return e.flange_translation_error_mm; }}};
  return measures;
}

std::string PadLeft(const std::string& text, size_t width) {
  return text.size() >= width ? text : std::string(width - text.size(), ' ') + text;
}
std::string PadRight(const std::string& text, size_t width) {
  return text.size() >= width ? text : text + std::string(width - text.size(), ' ');
}

}  // namespace

MeanStd ComputeMeanStd(const std::vector<double>& values) {
  if (values.empty()) return {};
  return {stats::Mean(values), stats::StdDev(values)};
}

Table1Row ComputeTable1Row(const std::vector<Eigen::Vector3d>& trial_axes_mm) {
  Table1Row row;
  row.num_trials = static_cast<int>(trial_axes_mm.size());
  for (int axis = 0; axis < 3; ++axis) {
    std::vector<double> values;
    for (const Eigen::Vector3d& t : trial_axes_mm) values.push_back(t[axis]);
    const MeanStd stats = ComputeMeanStd(values);
    row.axes_mean_mm[axis] = stats.mean;
    row.axes_std_mm[axis] = stats.std;
  }
  row.mean_mm = row.axes_mean_mm.norm();
  row.std_mm = row.axes_std_mm.norm();
  return row;
}

Table1Row SessionTable1Row(const SessionResult& session) {
  std::vector<Eigen::Vector3d> axes;
  for (const TrialResult& t : session.trials) axes.push_back(t.errors.misalignment_axes_mm);
  return ComputeTable1Row(axes);
}

std::optional<Table1Row> SessionViewerTable1Row(const SessionResult& session) {
  std::vector<Eigen::Vector3d> axes;
  for (const TrialResult& t : session.trials) {
    if (!t.errors.viewer_axes_mm) return std::nullopt;
    axes.push_back(*t.errors.viewer_axes_mm);
  }
  return ComputeTable1Row(axes);
}

std::string ResultsJson(const RunResults& r) {
  JsonWriter json(2);
  json.BeginObject();
  json.Key("run_id").String(r.run_id);
  json.Key("status").String(r.ok ? "ok" : r.partial ? "partial" : "failed");
  json.Key("error").String(r.error);
  if (!r.resumed_from.empty()) json.Key("resumed_from").String(r.resumed_from);
  if (!r.provenance.empty()) json.Key("provenance").String(r.provenance);
  json.Key("seed").Int(static_cast<int64_t>(r.seed));
  json.Key("started_utime").Int(r.started_utime);
  json.Key("duration_s").Number(r.duration_s);
  json.Key("translation_error_point")
      .String(
          "robot centroid: mean of the link origins from the base to the flange at the trial's q "
          "(for a mean: averaged over the session's configurations)");
  json.Key("misalignment_definition")
      .String(
          "paper Table 1: norm of the mean absolute per-axis error over the landmark pairs, "
          "||t_bar||_2 (orbed-registration MISALIGNMENT mean_error_norm_m); the pairs as the user "
          "annotated them by head gaze, triangulated by orbed-registration (landmarks \"gaze\"), or "
          "the link origins placed with the true X_WR and X_WV (landmarks \"truth\"; "
          "truth_misalignment_mm always); for a mean, over all the session's configurations: the real "
          "landmarks annotated in its trials against the virtual ones placed by the mean (landmarks "
          "\"gaze_real\"), or the truth's pairs when a trial has no annotation");
  json.Key("landmarks").BeginArray();
  for (const std::string& name : r.landmarks) json.String(name);
  json.EndArray();
  json.Key("configurations_deg").BeginArray();
  for (const auto& q : r.configurations_deg) json.Array(q);
  json.EndArray();
  json.Key("X_WR");
  if (r.X_WR) {
    WritePose(&json, *r.X_WR);
  } else {
    json.Null();
  }
  json.Key("rejected_inputs").Int(r.rejected_inputs);
  json.Key("paper_reference").BeginObject();
  json.Key("source").String(kPaperSource);
  json.Key("ar_reflective").BeginObject();
  json.Key("misalignment_mm")
      .Number(kPaperArReflective.misalignment_mm)
      .Key("std_mm")
      .Number(kPaperArReflective.std_mm);
  json.EndObject();
  json.Key("ar").BeginObject();
  json.Key("misalignment_mm").Number(kPaperAr.misalignment_mm).Key("std_mm").Number(kPaperAr.std_mm);
  json.EndObject();
  json.Key("ar_reflective_mean").BeginObject();
  json.Key("misalignment_mm")
      .Number(kPaperArReflectiveMean.misalignment_mm)
      .Key("std_mm")
      .Number(kPaperArReflectiveMean.std_mm);
  json.EndObject();
  json.EndObject();

  json.Key("sessions").BeginArray();
  for (const SessionResult& s : r.sessions) {
    json.BeginObject();
    json.Key("mode").String(s.mode);
    json.Key("session_id").String(s.session_id);
    json.Key("display_mode").Int(s.display_mode);
    json.Key("num_mirrors").Int(s.num_mirrors);
    if (!s.capture_waypoints.empty()) {
      json.Key("capture_waypoints").BeginArray();
      for (const std::string& w : s.capture_waypoints) json.String(w);
      json.EndArray();
    }
    json.Key("trials").BeginArray();
    for (const TrialResult& t : s.trials) {
      json.BeginObject();
      json.Key("index").Int(t.index);
      json.Key("q_deg").Array(t.q_deg);
      WriteMeasures(&json, t.errors);
      json.Key("user_duration_s").Number(t.user_duration_s);
      json.Key("user_id").String(t.user_id);
      json.Key("X_WV");
      WritePose(&json, t.X_WV);
      json.Key("X_WR");
      WritePose(&json, t.X_WR);
      if (t.viewer_eye_W_m) json.Key("viewer_eye_W_m").Array(Numbers(*t.viewer_eye_W_m));
      json.Key("annotated_real_W_m").BeginArray();
      for (const Eigen::Vector3d& p : t.annotated_real_W_m)
        json.Array(std::vector<double>{p.x(), p.y(), p.z()});
      json.EndArray();
      if (t.tracking_faults.any()) {
        json.Key("tracking_faults").BeginObject();
        json.Key("losses").Int(t.tracking_faults.losses);
        json.Key("relocalizations").Int(t.tracking_faults.relocalizations);
        json.Key("wait_s").Number(t.tracking_faults.wait_s);
        json.Key("repeats").Int(t.tracking_faults.repeats);
        json.EndObject();
      }
      json.EndObject();
    }
    json.EndArray();
    json.Key("trial_statistics").BeginObject();
    for (const auto& [name, get] : StatMeasures()) {
      std::vector<double> values;
      for (const TrialResult& t : s.trials) values.push_back(get(t.errors));
      const MeanStd stats = ComputeMeanStd(values);
      json.Key(name).BeginObject().Key("mean").Number(stats.mean).Key("std").Number(stats.std).EndObject();
    }
    json.EndObject();
    json.Key("table1");
    WriteTable1(&json, SessionTable1Row(s));
    if (const std::optional<Table1Row> viewer = SessionViewerTable1Row(s)) {
      json.Key("table1_viewer");
      WriteTable1(&json, *viewer);
    }
    json.Key("mean");
    if (s.mean) {
      const MeanResult& m = *s.mean;
      json.BeginObject();
      WriteMeasures(&json, m.errors);
      json.Key("X_WV");
      WritePose(&json, m.X_WV);
      json.Key("num_used").Int(m.num_used);
      json.Key("rejected_indices").Array(m.rejected_indices);
      json.Key("rotation_rms_deg").Number(m.rotation_rms_deg);
      json.Key("translation_rms_mm").Number(m.translation_rms_mm);
      json.Key("iterations").Int(m.iterations);
      json.Key("converged").Bool(m.converged);
      json.Key("unique").Bool(m.unique);
      json.EndObject();
    } else {
      json.Null();
    }
    json.EndObject();
  }
  json.EndArray();
  json.EndObject();
  return json.str() + "\n";
}

std::string ResultsTable(const RunResults& r) {
  std::ostringstream out;
  const auto row = [&](const std::string& mode, const std::string& what, const std::string& q,
                       const ErrorMeasures& e) {
    out << PadRight(mode, 15) << PadRight(what, 8) << PadRight(q, 44)
        << PadLeft(Fixed(e.translation_error_mm, 1), 9) << PadLeft(Fixed(e.rotation_error_deg, 2), 9)
        << PadLeft(Fixed(e.misalignment_mm, 1) + (e.landmarks == "gaze"        ? ""
                                                  : e.landmarks == "gaze_real" ? "^"
                                                                               : "*"),
                   10)
        << PadLeft(Fixed(e.truth_misalignment_mm, 1), 10) << PadLeft(Fixed(e.base_translation_error_mm, 1), 9)
        << "\n";
  };
  out << "ViRAAl run " << r.run_id << ": "
      << (r.ok        ? "ok"
          : r.partial ? "partial"
                      : "FAILED: " + r.error)
      << "  (" << Fixed(r.duration_s, 1) << " s)\n";
  out << PadRight("mode", 15) << PadRight("trial", 8) << PadRight("q [deg]", 44) << PadLeft("t [mm]", 9)
      << PadLeft("R [deg]", 9) << PadLeft("mis [mm]", 10) << PadLeft("true mis", 10) << PadLeft("base[mm]", 9)
      << "\n";
  for (const SessionResult& s : r.sessions) {
    std::vector<double> misalignment;
    for (const TrialResult& t : s.trials) {
      std::string q = "(";
      for (size_t i = 0; i < t.q_deg.size(); ++i) q += (i ? ", " : "") + Fixed(t.q_deg[i], 0);
      row(s.mode, std::to_string(t.index), q + ")", t.errors);
      misalignment.push_back(t.errors.misalignment_mm);
    }
    if (s.mean)
      row(s.mode, "mean", "SE(3) mean of " + std::to_string(s.mean->num_used) + " trials", s.mean->errors);
    const Table1Row table1 = SessionTable1Row(s);
    out << PadRight("", 23) << "Table 1 (" << table1.num_trials << " trials): " << Fixed(table1.mean_mm, 1)
        << " +/- " << Fixed(table1.std_mm, 1) << " mm";
    if (s.mode == "ar_reflective") {
      out << "   (paper: " << Fixed(kPaperArReflective.misalignment_mm, 1) << " +/- "
          << Fixed(kPaperArReflective.std_mm, 1) << " mm; its mean "
          << Fixed(kPaperArReflectiveMean.misalignment_mm, 1) << " +/- "
          << Fixed(kPaperArReflectiveMean.std_mm, 2) << " mm)";
    } else if (s.mode == "ar") {
      out << "   (paper: " << Fixed(kPaperAr.misalignment_mm, 1) << " +/- " << Fixed(kPaperAr.std_mm, 1)
          << " mm)";
    }
    const auto axes = [](const Eigen::Vector3d& v) {
      return "(" + Fixed(v.x(), 1) + ", " + Fixed(v.y(), 1) + ", " + Fixed(v.z(), 1) + ")";
    };
    out << "\n" << PadRight("", 23) << "per axis, means: W (x, y, z) " << axes(table1.axes_mean_mm);
    if (const std::optional<Table1Row> viewer = SessionViewerTable1Row(s)) {
      out << ", viewer S (across, down, line of sight) " << axes(viewer->axes_mean_mm) << " = "
          << Fixed(viewer->mean_mm, 1) << " +/- " << Fixed(viewer->std_mm, 1);
    }
    out << " mm";
    const MeanStd stats = ComputeMeanStd(misalignment);
    out << "\n"
        << PadRight("", 23) << "mean of the trials' mis " << Fixed(stats.mean, 1) << " +/- "
        << Fixed(stats.std, 1) << " mm\n";
  }
  out << "t = translation error at the robot centroid, R = rotation error, mis = a trial's landmark "
         "misalignment ||t_bar||_2 from the landmarks the user annotated by gaze (^ = an SE(3) mean: the "
         "real "
         "landmarks as annotated in the session's trials, the virtual ones placed by the mean; * = from the "
         "truth's landmarks: nobody annotated), true mis = the same from the truth's landmarks, "
         "base = translation error at the base origin; Table 1 = the paper's statistic: the norms of the "
         "per-axis means and standard deviations of t_bar over the trials\n";
  return out.str();
}

namespace {

constexpr size_t kMaxResultsBytes = 16 << 20;
constexpr int kMaxDepth = 8;
constexpr size_t kMaxName = 256;
constexpr size_t kMaxSessions = 16;
constexpr size_t kMaxTrials = 100000;
constexpr size_t kMaxJoints = 64;
constexpr double kMaxMeasure = 1e9;  // mm or deg: anything beyond is not a measure
constexpr double kMaxCoordinate = 1e4;
constexpr size_t kMaxAnnotatedLandmarks = 64;

Eigen::Isometry3d ReadPose(const JsonFields& f, const JsonAt& at) {
  const std::vector<double> p = f.Numbers(f.Member(at, "position_m"), 3, -kMaxCoordinate, kMaxCoordinate);
  const JsonAt q_at = f.Member(at, "quaternion_wxyz");
  const std::vector<double> q = f.Numbers(q_at, 4, -1.0, 1.0);
  const Eigen::Quaterniond quat(q[0], q[1], q[2], q[3]);
  if (std::abs(quat.norm() - 1.0) > 1e-6) f.Fail(q_at.key, "a unit quaternion");
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.linear() = quat.normalized().toRotationMatrix();
  X.translation() = Eigen::Vector3d(p[0], p[1], p[2]);
  return X;
}

ErrorMeasures ReadMeasures(const JsonFields& f, const JsonAt& at) {
  ErrorMeasures e;
  e.translation_error_mm = f.Number(f.Member(at, "translation_error_mm"), 0, kMaxMeasure);
  e.rotation_error_deg = f.Number(f.Member(at, "rotation_error_deg"), 0, 180);
  e.misalignment_mm = f.Number(f.Member(at, "misalignment_mm"), 0, kMaxMeasure);
  e.base_translation_error_mm = f.Number(f.Member(at, "base_translation_error_mm"), 0, kMaxMeasure);
  e.flange_translation_error_mm = f.Number(f.Member(at, "flange_translation_error_mm"), 0, kMaxMeasure);
  const std::vector<double> axes = f.Numbers(f.Member(at, "misalignment_axes_mm"), 3, 0, kMaxMeasure);
  e.misalignment_axes_mm = Eigen::Vector3d(axes[0], axes[1], axes[2]);
  e.misalignment_mean_pair_distance_mm =
      f.Number(f.Member(at, "misalignment_mean_pair_distance_mm"), 0, kMaxMeasure);
  e.landmarks = "truth";
  e.truth_misalignment_mm = e.misalignment_mm;
  if (const auto landmarks = f.OptionalMember(at, "landmarks")) {
    e.landmarks = f.String(*landmarks, 16);
    if (e.landmarks != "gaze" && e.landmarks != "gaze_real" && e.landmarks != "truth")
      f.Fail(landmarks->key, "\"gaze\", \"gaze_real\" or \"truth\"", &landmarks->value);
  }
  if (const auto truth = f.OptionalMember(at, "truth_misalignment_mm")) {
    e.truth_misalignment_mm = f.Number(*truth, 0, kMaxMeasure);
  }
  if (const auto viewer = f.OptionalMember(at, "viewer_axes_mm")) {
    const std::vector<double> v = f.Numbers(*viewer, 3, 0, kMaxMeasure);
    e.viewer_axes_mm = Eigen::Vector3d(v[0], v[1], v[2]);
  }
  return e;
}

std::vector<double> ReadJoints(const JsonFields& f, const JsonAt& at) {
  return f.Numbers(at, f.ArraySize(at, kMaxJoints), -360, 360);
}

}  // namespace

RunResults ParseResultsJson(const std::string& text, const std::string& source) {
  const JsonFields f(source);
  const nlohmann::json doc = f.Parse(text, kMaxResultsBytes, kMaxDepth);
  const JsonAt root{doc, ""};
  RunResults r;
  r.run_id = f.String(f.Member(root, "run_id"), kMaxName);
  const JsonAt status = f.Member(root, "status");
  const std::string status_text = f.String(status, kMaxName);
  if (status_text != "ok" && status_text != "failed" && status_text != "partial") {
    f.Fail(status.key, "ok, failed or partial", &status.value);
  }
  r.ok = status_text == "ok";
  r.partial = status_text == "partial";
  r.error = f.String(f.Member(root, "error"), 1 << 16);
  if (const auto from = f.OptionalMember(root, "resumed_from")) r.resumed_from = f.String(*from, 1 << 12);
  if (const auto record = f.OptionalMember(root, "provenance")) r.provenance = f.String(*record, 1 << 12);
  r.seed = static_cast<uint64_t>(f.Integer(f.Member(root, "seed"), std::numeric_limits<int64_t>::min(),
                                           std::numeric_limits<int64_t>::max()));
  // The run's times (absent from a pinned file, which leaves them out).
  if (const auto started = f.OptionalMember(root, "started_utime")) {
    r.started_utime = f.Integer(*started, 0, std::numeric_limits<int64_t>::max());
  }
  if (const auto duration = f.OptionalMember(root, "duration_s")) r.duration_s = f.Number(*duration, 0, 1e9);
  const JsonAt landmarks = f.Member(root, "landmarks");
  for (size_t i = 0, n = f.ArraySize(landmarks, kMaxName); i < n; ++i) {
    r.landmarks.push_back(f.String(f.Element(landmarks, i), kMaxName));
  }
  const JsonAt configurations = f.Member(root, "configurations_deg");
  for (size_t i = 0, n = f.ArraySize(configurations, kMaxTrials); i < n; ++i) {
    r.configurations_deg.push_back(ReadJoints(f, f.Element(configurations, i)));
  }
  if (const auto X_WR = f.OptionalMember(root, "X_WR")) r.X_WR = ReadPose(f, *X_WR);
  r.rejected_inputs = f.Integer(f.Member(root, "rejected_inputs"), 0, std::numeric_limits<int64_t>::max());
  const JsonAt sessions = f.Member(root, "sessions");
  for (size_t i = 0, n = f.ArraySize(sessions, kMaxSessions); i < n; ++i) {
    const JsonAt at = f.Element(sessions, i);
    SessionResult s;
    s.mode = f.String(f.Member(at, "mode"), kMaxName);
    s.session_id = f.String(f.Member(at, "session_id"), kMaxName);
    s.display_mode = static_cast<int>(f.Integer(f.Member(at, "display_mode"), 0, 1));
    s.num_mirrors = static_cast<int>(f.Integer(f.Member(at, "num_mirrors"), 0, 64));
    if (const auto waypoints = f.OptionalMember(at, "capture_waypoints")) {
      for (size_t k = 0, m = f.ArraySize(*waypoints, static_cast<size_t>(s.num_mirrors)); k < m; ++k) {
        const JsonAt w = f.Element(*waypoints, k);
        s.capture_waypoints.push_back(f.String(w, kMaxWaypointNameLength));
        if (!IsWaypointName(s.capture_waypoints.back()))
          f.Fail(w.key, "a waypoint name (printable, no spaces)", &w.value);
      }
      if (static_cast<int>(s.capture_waypoints.size()) != s.num_mirrors)
        f.Fail(waypoints->key, "one waypoint per display (" + std::to_string(s.num_mirrors) + ")");
    }
    const JsonAt trials = f.Member(at, "trials");
    for (size_t k = 0, m = f.ArraySize(trials, kMaxTrials); k < m; ++k) {
      const JsonAt t_at = f.Element(trials, k);
      TrialResult t;
      t.index = static_cast<int>(f.Integer(f.Member(t_at, "index"), 0, kMaxTrials));
      t.q_deg = ReadJoints(f, f.Member(t_at, "q_deg"));
      t.errors = ReadMeasures(f, t_at);
      t.user_duration_s = f.Number(f.Member(t_at, "user_duration_s"), 0, 1e9);
      t.user_id = f.String(f.Member(t_at, "user_id"), kMaxName);
      t.X_WV = ReadPose(f, f.Member(t_at, "X_WV"));
      t.X_WR = ReadPose(f, f.Member(t_at, "X_WR"));
      if (const auto eye = f.OptionalMember(t_at, "viewer_eye_W_m")) {
        const std::vector<double> p = f.Numbers(*eye, 3, -kMaxCoordinate, kMaxCoordinate);
        t.viewer_eye_W_m = Eigen::Vector3d(p[0], p[1], p[2]);
      }
      if (const auto annotated = f.OptionalMember(t_at, "annotated_real_W_m")) {
        for (size_t l = 0, n = f.ArraySize(*annotated, kMaxAnnotatedLandmarks); l < n; ++l) {
          const std::vector<double> p =
              f.Numbers(f.Element(*annotated, l), 3, -kMaxCoordinate, kMaxCoordinate);
          t.annotated_real_W_m.emplace_back(p[0], p[1], p[2]);
        }
      }
      if (const auto faults = f.OptionalMember(t_at, "tracking_faults")) {
        t.tracking_faults.losses = static_cast<int>(f.Integer(f.Member(*faults, "losses"), 0, 1000000));
        t.tracking_faults.relocalizations =
            static_cast<int>(f.Integer(f.Member(*faults, "relocalizations"), 0, 1000000));
        t.tracking_faults.wait_s = f.Number(f.Member(*faults, "wait_s"), 0, t.user_duration_s);
        t.tracking_faults.repeats = static_cast<int>(f.Integer(f.Member(*faults, "repeats"), 0, 1000000));
      }
      s.trials.push_back(t);
    }
    if (const auto mean_at = f.OptionalMember(at, "mean")) {
      MeanResult mean;
      mean.errors = ReadMeasures(f, *mean_at);
      mean.X_WV = ReadPose(f, f.Member(*mean_at, "X_WV"));
      mean.num_used = static_cast<int>(f.Integer(f.Member(*mean_at, "num_used"), 0, kMaxTrials));
      const JsonAt rejected = f.Member(*mean_at, "rejected_indices");
      for (size_t k = 0, m = f.ArraySize(rejected, kMaxTrials); k < m; ++k) {
        mean.rejected_indices.push_back(static_cast<int>(f.Integer(f.Element(rejected, k), 0, kMaxTrials)));
      }
      mean.rotation_rms_deg = f.Number(f.Member(*mean_at, "rotation_rms_deg"), 0, 180);
      mean.translation_rms_mm = f.Number(f.Member(*mean_at, "translation_rms_mm"), 0, kMaxMeasure);
      mean.iterations = static_cast<int>(f.Integer(f.Member(*mean_at, "iterations"), 0, 1 << 20));
      mean.converged = f.Bool(f.Member(*mean_at, "converged"));
      mean.unique = f.Bool(f.Member(*mean_at, "unique"));
      s.mean = mean;
    }
    r.sessions.push_back(s);
  }
  return r;
}

RunResults ReadResultsFile(const std::string& path) {
  std::string file = path;
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) file = (std::filesystem::path(path) / "results.json").string();
  std::ifstream in(file, std::ios::binary);
  if (!in) throw JsonReadError(file + ": cannot read it");
  std::string text(kMaxResultsBytes + 1, '\0');
  in.read(text.data(), static_cast<std::streamsize>(text.size()));
  text.resize(static_cast<size_t>(in.gcount()));
  return ParseResultsJson(text, file);
}

std::string WriteResultsFile(const std::string& dir, const std::string& text) {
  const std::string path = (dir.empty() ? std::string(".") : dir) + "/results.json";
  std::string error;
  if (!ReplaceFile(path, text, &error)) throw std::runtime_error(error);
  return path;
}

}  // namespace orbed::viraal
