#include "procs/hl2ss/depth_stream.h"

#include <chrono>
#include <exception>
#include <utility>

#include "base/source_paths.h"
#include "lcmtypes/contract/conversions.h"
#include "lcmtypes/contract/validation.h"
#include "procs/hl2ss/frames.h"
#include "render/scene_geometry.h"
#include "sim/iiwa_status_check.h"
#include "sim/scene.h"

namespace orbed::hl2ss {
namespace {

constexpr double kJointLimitSlackRad = 0.01;  // as orbed-hmd: the sim clamps, rounding aside

std::optional<Refusal> Refuse(const std::string& key, const std::string& reason) {
  return Refusal{key, reason};
}

}  // namespace

DepthStream::DepthStream(const DepthStreamOptions& options, const TimeBase& time_base)
    : options_(options), time_base_(time_base) {
  const std::string urdf = options_.urdf_path.empty()
                               ? SourceTreePath(sim::RobotModel::kDefaultUrdfRelativePath)
                               : options_.urdf_path;
  const std::optional<sim::Scene> scene = sim::LoadSceneFlag(options_.scene_path);
  robot_ = std::make_unique<sim::RobotModel>(scene ? sim::LoadRobotForScene(urdf, *scene)
                                                   : sim::RobotModel::LoadFile(urdf));
  render::SceneGeometry objects;
  if (scene) objects.AddSceneObjects(*scene);
  room_ = std::make_unique<render::RoomMesh>(*robot_, objects);
  camera_ = std::make_unique<LongThrowCamera>(options_.camera);
  calibration_ = PackLongThrowCalibration(options_.camera);
  worker_ = std::thread([this] { WorkerLoop(); });
}

DepthStream::~DepthStream() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  worker_.join();
}

std::optional<Refusal> DepthStream::OnJoints(const orbed::iiwa_status_t& msg) {
  Eigen::VectorXd q;
  const sim::IiwaStatusProblem problem = sim::CheckIiwaStatus(msg, *robot_, kJointLimitSlackRad, &q);
  if (!problem.rejection_class.empty()) return Refuse(problem.rejection_class, problem.reason);
  q_rad_ = std::move(q);
  return std::nullopt;
}

std::optional<Refusal> DepthStream::OnRobotState(const orbed::robot_state_t& msg) {
  const std::string error = CheckPose(msg.X_WR, "X_WR");
  if (!error.empty()) return Refuse("pose", error);
  X_WR_ = FromPose(msg.X_WR);
  return std::nullopt;
}

std::optional<Refusal> DepthStream::OnTruth(const orbed::hmd_pose_t& msg, int64_t now_us) {
  const std::string error = CheckWorldPose(msg.X_WH, "X_WH");
  if (!error.empty()) return Refuse("field", error);
  truths_[msg.utime] = Truth{FromPose(msg.X_WH), now_us};
  if (truths_.size() > kKeptPoses) truths_.erase(truths_.begin());
  return std::nullopt;
}

void DepthStream::OnEstimate(const Eigen::Isometry3d& X_WH, int64_t utime) {
  estimates_[utime] = X_WH;
  if (estimates_.size() > kKeptPoses) estimates_.erase(estimates_.begin());
}

Decision DepthStream::Configure(int client, const RmDepthLongThrowConfig& config) {
  Decision d;
  if (config.mode == kMode2) {
    d.kind = Decision::kReplyAndClose;
    d.reply = calibration_;
    return d;
  }
  // The PNG filter is the client's hint to the encoder; OpenCV chooses its own (any filter
  // decodes to the same pixels).
  clients_[client] = Client{config.mode, config.divisor, 0};
  return d;
}

bool DepthStream::Tick(int64_t now_us) {
  if (clients_.empty() || truths_.empty()) return false;
  if (now_us - truths_.rbegin()->second.received_us > static_cast<int64_t>(options_.stale_s * 1e6))
    return false;
  Job job;
  for (auto& [id, c] : clients_) {
    if (c.ticks++ % c.divisor != 0) continue;
    (c.mode == kMode0 ? job.mode0 : job.mode1).push_back(id);
  }
  if (job.mode0.empty() && job.mode1.empty()) return false;
  job.robot_known = q_rad_ && X_WR_;
  if (job.robot_known) {
    job.q_rad = *q_rad_;
    job.X_WR = *X_WR_;
  }
  // The newest truth whose estimate has come; else the newest with the newest estimate (else itself).
  auto truth = truths_.rbegin();
  while (truth != truths_.rend() && !estimates_.count(truth->first)) ++truth;
  if (truth != truths_.rend()) {
    job.X_WH_estimate = estimates_.at(truth->first);
  } else {
    truth = truths_.rbegin();
    job.X_WH_estimate = estimates_.empty() ? truth->second.X_WH : estimates_.rbegin()->second;
  }
  job.X_WH_true = truth->second.X_WH;
  job.stamp = time_base_.TicksOf(truth->first);
  bool replaced = false;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    replaced = job_.has_value();
    job_ = std::move(job);
  }
  wake_.notify_all();
  return replaced;
}

std::optional<DepthPackets> DepthStream::TakeReady() {
  std::lock_guard<std::mutex> lock(mutex_);
  std::optional<DepthPackets> out = std::move(ready_);
  ready_.reset();
  return out;
}

bool DepthStream::WaitReady(double timeout_s) {
  std::unique_lock<std::mutex> lock(mutex_);
  return ready_cv_.wait_for(lock, std::chrono::duration<double>(timeout_s),
                            [this] { return ready_.has_value(); });
}

int64_t DepthStream::frames_rendered() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return rendered_;
}

void DepthStream::WorkerLoop() {
  std::unique_lock<std::mutex> lock(mutex_);
  for (;;) {
    wake_.wait(lock, [this] { return stop_ || job_.has_value(); });
    if (stop_) return;
    const Job job = std::move(*job_);
    job_.reset();
    lock.unlock();
    DepthPackets packets = Make(job);
    lock.lock();
    ++rendered_;
    ready_ = std::move(packets);  // an untaken frame is older: replaced
    ready_cv_.notify_all();
  }
}

DepthPackets DepthStream::Make(const Job& job) {
  DepthPackets out;
  out.stamp = job.stamp;
  try {
    if (!job.robot_known) {
      if (posed_) room_->ClearRobot();
      posed_ = false;
    } else if (!posed_ || posed_q_ != job.q_rad || posed_X_WR_.matrix() != job.X_WR.matrix()) {
      room_->PoseRobot(job.q_rad, job.X_WR);
      posed_ = true;
      posed_q_ = job.q_rad;
      posed_X_WR_ = job.X_WR;
    }
    camera_->Render(room_->mesh(), job.X_WH_true, &frame_);
    std::vector<uint8_t> payload;
    if (!EncodeLongThrowPayload(frame_, job.stamp, &payload, &out.error)) return out;
    if (!job.mode1.empty()) {
      const std::array<float, 16> pose =
          PoseMatrixRowMajor(RigNodePoseForClient(job.X_WH_estimate, options_.camera));
      out.packet1 = PackPacket(job.stamp, payload, &pose);
    }
    if (!job.mode0.empty()) out.packet0 = PackPacket(job.stamp, payload, nullptr);
    out.mode0 = job.mode0;
    out.mode1 = job.mode1;
  } catch (const std::exception& e) {
    out.error = std::string("rm_depth: ") + e.what();
  }
  return out;
}

}  // namespace orbed::hl2ss
