#include "hmd_emulator/interactive.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <opencv2/imgproc.hpp>

#include "base/units.h"

namespace orbed::hmd {
namespace {

void Rotate(const Eigen::Vector3d& axis_W, double angle_rad, Eigen::Isometry3d* X_WV) {
  X_WV->linear() = Eigen::AngleAxisd(angle_rad, axis_W).toRotationMatrix() * X_WV->linear();
}

void Text(cv::Mat* image, const std::string& text, cv::Point at, double scale, cv::Scalar color,
          int thickness = 1) {
  cv::putText(*image, text, at, cv::FONT_HERSHEY_SIMPLEX, scale, color, thickness, cv::LINE_AA);
}

cv::Mat Panel(const cv::Mat& image, int width, int height, const std::string& title,
              const std::string& empty_text) {
  cv::Mat panel(height, width, CV_8UC3, cv::Scalar(40, 40, 40));
  if (!image.empty() && image.type() == CV_8UC3) {
    cv::resize(image, panel, cv::Size(width, height), 0, 0, cv::INTER_AREA);
  } else {
    Text(&panel, empty_text, cv::Point(20, height / 2), 0.7, cv::Scalar(200, 200, 200));
  }
  cv::rectangle(panel, cv::Rect(0, 0, width, 28), cv::Scalar(25, 25, 25), cv::FILLED);
  Text(&panel, title, cv::Point(10, 20), 0.58, cv::Scalar(235, 235, 235));
  return panel;
}

// The direction of a joint key: ',' turns back, '.' forward.
double ApplyKeySign(int key) { return (key & 0xFF) == ',' ? -1.0 : 1.0; }

}  // namespace

KeyAction ApplyKey(int key, int num_displays, InteractiveState* s, Eigen::Isometry3d* X_WV, int num_joints) {
  const double t = s->step_m, r = s->step_deg * kDegToRad;
  const int k = key & 0xFF;
  if (k >= '1' && k <= '9') {
    if (k - '1' >= num_joints) return KeyAction::kNone;
    s->selected_joint = k - '1';
    return KeyAction::kSelectJoint;
  }
  switch (k) {
    case 't':
      s->edit_target = !s->edit_target;
      return KeyAction::kToggleTarget;
    case ',':
      return KeyAction::kJointMinus;
    case '.':
      return KeyAction::kJointPlus;
    case 'a':
      X_WV->translation().x() -= t;
      return KeyAction::kMoved;
    case 'd':
      X_WV->translation().x() += t;
      return KeyAction::kMoved;
    case 'w':
      X_WV->translation().y() += t;
      return KeyAction::kMoved;
    case 's':
      X_WV->translation().y() -= t;
      return KeyAction::kMoved;
    case 'r':
      X_WV->translation().z() += t;
      return KeyAction::kMoved;
    case 'f':
      X_WV->translation().z() -= t;
      return KeyAction::kMoved;
    case 'j':
      Rotate(Eigen::Vector3d::UnitZ(), -r, X_WV);
      return KeyAction::kMoved;
    case 'l':
      Rotate(Eigen::Vector3d::UnitZ(), r, X_WV);
      return KeyAction::kMoved;
    case 'i':
      Rotate(Eigen::Vector3d::UnitY(), r, X_WV);
      return KeyAction::kMoved;
    case 'k':
      Rotate(Eigen::Vector3d::UnitY(), -r, X_WV);
      return KeyAction::kMoved;
    case 'u':
      Rotate(Eigen::Vector3d::UnitX(), -r, X_WV);
      return KeyAction::kMoved;
    case 'o':
      Rotate(Eigen::Vector3d::UnitX(), r, X_WV);
      return KeyAction::kMoved;
    case '[':
      s->step_m = std::max(0.0005, s->step_m / 2);
      return KeyAction::kStep;
    case ']':
      s->step_m = std::min(0.1, s->step_m * 2);
      return KeyAction::kStep;
    case '-':
      s->step_deg = std::max(0.05, s->step_deg / 2);
      return KeyAction::kStep;
    case '=':
      s->step_deg = std::min(10.0, s->step_deg * 2);
      return KeyAction::kStep;
    case 'h':
      s->show_help = !s->show_help;
      return KeyAction::kHelp;
    case '0':
      return KeyAction::kReset;
    case 'n':
      s->shown_display = num_displays > 0 ? (s->shown_display + 1) % num_displays : 0;
      return KeyAction::kNextDisplay;
    case 'c':
      return KeyAction::kRecapture;
    case 10:
    case 13:
      return KeyAction::kSubmit;
    case 'q':
    case 27:
      return KeyAction::kQuit;
    default:
      return KeyAction::kNone;
  }
}

std::vector<std::string> InteractiveHelpLines() {
  return {
      "a / d    move the virtual robot along -x / +x (world)",
      "w / s    along +y / -y          r / f    along +z / -z",
      "j / l    yaw -/+ (about z)      i / k    pitch +/- (about y)",
      "u / o    roll -/+ (about x)     (about the world axes through V's origin)",
      "[ / ]    translation step /2, x2          - / =    rotation step /2, x2",
      "0        back to the start pose           n        next reflective display",
      "c        re-capture the shown display from where you stand",
      "Enter    submit the alignment trial (ALIGNMENT_TRIAL)",
      "h        this help on/off                 q / Esc  quit",
      "1 .. 7   select a joint of the real arm   , / .    turn it -/+ by the rotation step",
      "t        plan the target instead (, / . turn its joints, Enter sends it); t: back to the arm",
  };
}

cv::Mat WindowImage(const cv::Mat& ar_view, const cv::Mat& reflective, const InteractiveState& state,
                    const std::vector<std::string>& status_lines, int panel_width_px) {
  const int w = std::max(160, panel_width_px);
  const int h = w * 9 / 16;
  const int bar_h = 34 + 24 * static_cast<int>(status_lines.size());
  cv::Mat window(h + bar_h, 2 * w, CV_8UC3, cv::Scalar(30, 30, 30));
  Panel(ar_view, w, h, "AR view: the hologram over the live camera frame", "waiting for the camera")
      .copyTo(window(cv::Rect(0, 0, w, h)));
  char title[96];
  std::snprintf(title, sizeof(title), "reflective display %d (mirror view of a captured frame)",
                state.shown_display);
  Panel(reflective, w, h, title, "no reflective display (--displays 0) or no frame yet")
      .copyTo(window(cv::Rect(w, 0, w, h)));
  cv::line(window, cv::Point(w, 0), cv::Point(w, h), cv::Scalar(90, 90, 90), 2);

  char steps[160];
  std::snprintf(steps, sizeof(steps),
                "step: %.1f mm  %.2f deg   ([ ] and - = change them)   h: help   Enter: submit   q: quit",
                state.step_m * 1e3, state.step_deg);
  Text(&window, steps, cv::Point(12, h + 24), 0.6, cv::Scalar(120, 230, 255));
  for (std::size_t i = 0; i < status_lines.size(); ++i) {
    Text(&window, status_lines[i], cv::Point(12, h + 48 + 24 * static_cast<int>(i)), 0.55,
         cv::Scalar(225, 225, 225));
  }

  if (state.show_help) {
    const std::vector<std::string> lines = InteractiveHelpLines();
    const int box_w = std::min(2 * w - 40, 760), box_h = 50 + 26 * static_cast<int>(lines.size());
    const cv::Rect box((2 * w - box_w) / 2, std::max(10, (h - box_h) / 2), box_w, box_h);
    cv::Mat roi = window(box & cv::Rect(0, 0, window.cols, window.rows));
    cv::Mat dark(roi.size(), CV_8UC3, cv::Scalar(20, 20, 20));
    cv::addWeighted(roi, 0.2, dark, 0.8, 0, roi);
    cv::rectangle(window, box, cv::Scalar(120, 230, 255), 1);
    Text(&window, "keys", cv::Point(box.x + 16, box.y + 30), 0.7, cv::Scalar(120, 230, 255), 2);
    for (std::size_t i = 0; i < lines.size(); ++i) {
      Text(&window, lines[i], cv::Point(box.x + 16, box.y + 58 + 26 * static_cast<int>(i)), 0.55,
           cv::Scalar(240, 240, 240));
    }
  }
  return window;
}

std::vector<int> ScriptedKeys(const std::string& text) {
  std::vector<int> keys;
  for (std::size_t i = 0; i < text.size(); ++i) {
    if (text[i] == '\\' && i + 1 < text.size() && (text[i + 1] == 'n' || text[i + 1] == 'e')) {
      keys.push_back(text[++i] == 'n' ? 13 : 27);
    } else {
      keys.push_back(static_cast<unsigned char>(text[i]));
    }
  }
  return keys;
}

InteractiveSession::InteractiveSession(int num_displays, const Eigen::Isometry3d& X_WV_start,
                                       const std::string& scripted_keys, double now_s, int num_joints)
    : num_displays_(num_displays),
      X_WV_start_(X_WV_start),
      X_WV_(X_WV_start),
      scripted_(ScriptedKeys(scripted_keys)),
      trial_started_s_(now_s),
      num_joints_(num_joints) {}

InteractiveSession::Request InteractiveSession::HandleKey(int key) {
  switch (ApplyKey(key, num_displays_, &ui_, &X_WV_, num_joints_)) {
    case KeyAction::kSelectJoint:
      last_event_ = "joint " + std::to_string(ui_.selected_joint + 1) + " selected (, and . turn it)";
      return Request::kNone;
    case KeyAction::kJointMinus:
    case KeyAction::kJointPlus:
      joint_step_rad_ = (ApplyKeySign(key) * ui_.step_deg) * kDegToRad;
      return ui_.edit_target ? Request::kMoveTarget : Request::kMoveJoint;
    case KeyAction::kToggleTarget:
      last_event_ = ui_.edit_target ? "planning the target: , and . turn its joints, Enter sends it"
                                    : "back to the arm: , and . turn its joints";
      return Request::kEditTarget;
    case KeyAction::kReset:
      X_WV_ = X_WV_start_;
      last_event_ = "back at the start pose";
      return Request::kNone;
    case KeyAction::kRecapture:
      last_event_ = "display " + std::to_string(ui_.shown_display) + " re-captured from here";
      return Request::kRecapture;
    case KeyAction::kQuit:
      return Request::kQuit;
    case KeyAction::kSubmit:
      return ui_.edit_target ? Request::kSendTarget : Request::kSubmit;
    default:
      return Request::kNone;
  }
}

int InteractiveSession::NextScriptedKey() {
  return scripted_next_ < scripted_.size() ? scripted_[scripted_next_++] : -1;
}

const std::string& InteractiveSession::TrialRequested(const std::string& session_id, int32_t index,
                                                      double now_s) {
  trial_requested_ = true;
  trial_started_s_ = now_s;
  last_event_ = "trial " + std::to_string(index) + " of '" + session_id +
                "' requested: align the hologram, then press Enter";
  return last_event_;
}

double InteractiveSession::Submitted(const std::string& session_id, int32_t index, double now_s) {
  const double duration_s = now_s - trial_started_s_;
  trial_requested_ = false;
  trial_started_s_ = now_s;
  char seconds[32];
  std::snprintf(seconds, sizeof(seconds), "%.1f", duration_s);
  last_event_ = "submitted trial " + std::to_string(index) + " of '" + session_id + "' (" + seconds + " s)";
  return duration_s;
}

std::string GuidanceLine(const std::string& mode, const std::vector<double>& error_deg, int next_joint,
                         bool done) {
  std::string line = "guidance (" + mode + "): ";
  line += done ? std::string("done") : "next joint " + std::to_string(next_joint + 1);
  line += " | error [deg]";
  char cell[16];
  for (double e : error_deg) {
    std::snprintf(cell, sizeof(cell), " %+.1f", e);
    line += cell;
  }
  return line;
}

cv::Mat InteractiveSession::Window(const cv::Mat& ar_view, const cv::Mat& reflective,
                                   const HmdSessionState& session, const Eigen::Isometry3d& X_WV_shown,
                                   bool robot_known, const std::string& tracking,
                                   const std::string& guidance) const {
  std::vector<std::string> lines;
  std::string line = session.active()
                         ? session.Describe() + ", next trial " + std::to_string(session.next_index)
                         : std::string("no session (Enter starts a local one)");
  if (trial_requested_) line += "   >> TRIAL REQUESTED: align, then Enter <<";
  lines.push_back(line);
  const Eigen::Isometry3d& X_WV = X_WV_shown;
  const Eigen::Vector3d dp_mm = (X_WV.translation() - X_WV_start_.translation()) * 1e3;
  const double dtheta_deg =
      Eigen::AngleAxisd(X_WV_start_.linear().transpose() * X_WV.linear()).angle() * kRadToDeg;
  char text[256];
  std::snprintf(text, sizeof(text),
                "X_WV from the start pose: (%+.1f, %+.1f, %+.1f) mm, %.2f deg   robot: %s   tracking: %s",
                dp_mm.x(), dp_mm.y(), dp_mm.z(), dtheta_deg,
                robot_known ? "live" : "waiting for IIWA_STATUS + ROBOT_STATE", tracking.c_str());
  lines.push_back(text);
  lines.push_back((guidance.empty() ? std::string("guidance: none") : guidance) +
                  (ui_.edit_target ? "   PLANNING the target: joint " : "   arm: joint ") +
                  std::to_string(ui_.selected_joint + 1) + " selected");
  lines.push_back(last_event_.empty() ? std::string(" ") : last_event_);
  return WindowImage(ar_view, reflective, ui_, lines);
}

}  // namespace orbed::hmd
