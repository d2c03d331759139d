#include "procs/hl2ss/unity_scene.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <utility>

#include "base/format.h"
#include "lcmtypes/contract/conversions.h"
#include "procs/hl2ss/frames.h"

namespace orbed::hl2ss {
namespace {

constexpr std::size_t kMaxDebugMessageBytes = 256;

std::uint32_t LoadU32(const std::uint8_t* p) {
  return static_cast<std::uint32_t>(p[0]) | static_cast<std::uint32_t>(p[1]) << 8 |
         static_cast<std::uint32_t>(p[2]) << 16 | static_cast<std::uint32_t>(p[3]) << 24;
}

float LoadF32(const std::uint8_t* p) {
  const std::uint32_t bits = LoadU32(p);
  float f;
  std::memcpy(&f, &bits, sizeof(f));
  return f;
}

void AppendU32(std::uint32_t v, std::vector<std::uint8_t>* out) {
  for (int i = 0; i < 4; ++i) out->push_back(static_cast<std::uint8_t>(v >> (8 * i)));
}

std::string KeyText(std::int32_t key) { return std::to_string(static_cast<std::uint32_t>(key)); }

}  // namespace

Eigen::Isometry3d PoseFromUnity(const Eigen::Vector3d& p_U, const Eigen::Vector4d& q_U_xyzw) {
  Eigen::Isometry3d X_DG = Eigen::Isometry3d::Identity();
  X_DG.linear() = q_D_FromUnity(q_U_xyzw[0], q_U_xyzw[1], q_U_xyzw[2], q_U_xyzw[3]).toRotationMatrix();
  X_DG.translation() = p_D_FromUnity(p_U);
  return X_WD() * X_DG;
}

UnityScene::UnityScene(const UnitySceneLimits& limits) : limits_(limits) {
  if (limits.max_objects < 1 || limits.max_objects > orbed::hologram_scene_t::MAX_HOLOGRAMS)
    throw std::invalid_argument("unity scene: max_objects must be in [1, " +
                                std::to_string(orbed::hologram_scene_t::MAX_HOLOGRAMS) + "]");
  if (limits.max_command_bytes < 64)
    throw std::invalid_argument("unity scene: max_command_bytes must be >= 64");
  if (!(limits.max_position_m > 0) || !(limits.max_scale > 0))
    throw std::invalid_argument("unity scene: max_position_m and max_scale must be > 0");
}

bool UmqSession::Consume(const std::uint8_t* data, std::size_t size, std::vector<std::uint8_t>* reply) {
  while (size > 0 && !closed_) {
    if (header_got_ < header_.size()) {
      const std::size_t take = std::min(header_.size() - header_got_, size);
      std::memcpy(header_.data() + header_got_, data, take);
      header_got_ += take;
      data += take;
      size -= take;
      if (header_got_ < header_.size()) break;
      id_ = LoadU32(header_.data());
      size_ = LoadU32(header_.data() + 4);
      data_got_ = 0;
      if (size_ > scene_->limits_.max_command_bytes) {
        Refuse("size", "command " + std::to_string(id_) + " of " + std::to_string(size_) +
                           " bytes (at most " + std::to_string(scene_->limits_.max_command_bytes) +
                           "): closing the connection");
        closed_ = true;
        break;
      }
    } else {
      const std::size_t take = std::min<std::size_t>(size_ - data_got_, size);
      if (data_got_ < kHeadBytes) {
        const std::size_t keep = std::min<std::size_t>(kHeadBytes - data_got_, take);
        std::memcpy(head_.data() + data_got_, data, keep);
      }
      data_got_ += static_cast<std::uint32_t>(take);
      data += take;
      size -= take;
    }
    if (header_got_ == header_.size() && data_got_ == size_) {
      AppendU32(Execute(id_), reply);
      ++commands_;
      header_got_ = 0;
    }
  }
  return !closed_;
}

void UmqSession::OnDisconnect() {
  use_last_ = false;
  last_key_ = 0;
  in_display_list_ = false;
  header_got_ = 0;
  data_got_ = 0;
}

std::vector<Refusal> UmqSession::TakeRefusals() { return std::exchange(refusals_, {}); }

std::uint32_t UmqSession::Refuse(const std::string& key, const std::string& reason) {
  refusals_.push_back(Refusal{key, reason});
  return 0;
}

bool UmqSession::Short(std::size_t need, const char* command) {
  if (size_ >= need) return false;
  Refuse("short", std::string(command) + ": " + std::to_string(size_) + " bytes of data, needs " +
                      std::to_string(need));
  return true;
}

std::uint32_t UmqSession::CreateObject(ObjectKind kind) {
  UnityScene& s = *scene_;
  if (static_cast<int>(s.objects_.size()) >= s.limits_.max_objects) {
    Refuse("objects", "create: the scene holds " + std::to_string(s.objects_.size()) + " objects (at most " +
                          std::to_string(s.limits_.max_objects) + ")");
    return 0;
  }
  if (s.next_key_ > std::numeric_limits<std::int32_t>::max()) {
    Refuse("objects", "create: every key has been used");
    return 0;
  }
  const auto key = static_cast<std::int32_t>(s.next_key_++);
  UnityObject object;
  object.kind = kind;
  s.objects_.emplace(key, object);
  last_key_ = key;
  ++s.revision_;
  return static_cast<std::uint32_t>(key);
}

UnityObject* UmqSession::Target(const char* command) {
  const std::int32_t key = use_last_ ? last_key_ : static_cast<std::int32_t>(LoadU32(head_.data()));
  const auto it = scene_->objects_.find(key);
  if (it == scene_->objects_.end()) {
    Refuse("unknown_key", std::string(command) + ": no object " + KeyText(key));
    return nullptr;
  }
  return &it->second;
}

std::uint32_t UmqSession::SetTransform() {
  if (Short(44, "set transform")) return 0;
  UnityObject* object = Target("set transform");
  if (!object) return 0;
  double f[10];
  for (int i = 0; i < 10; ++i) {
    f[i] = LoadF32(head_.data() + 4 + 4 * i);
    if (!std::isfinite(f[i]))
      return Refuse("non_finite", "set transform: value " + std::to_string(i) + " not finite");
  }
  const Eigen::Vector3d p_U(f[0], f[1], f[2]);
  const Eigen::Vector4d q_U(f[3], f[4], f[5], f[6]);
  const Eigen::Vector3d scale(f[7], f[8], f[9]);
  const UnitySceneLimits& limits = scene_->limits_;
  if (p_U.norm() > limits.max_position_m)
    return Refuse("range", "set transform: position " + Fixed(p_U.norm(), 1) + " m from the origin");
  if (scale.cwiseAbs().maxCoeff() > limits.max_scale)
    return Refuse("range", "set transform: scale beyond " + Fixed(limits.max_scale, 0));
  if (!(q_U.norm() >= 1e-6)) return Refuse("range", "set transform: rotation of norm < 1e-6");
  const Eigen::Isometry3d X_WG = PoseFromUnity(p_U, q_U);
  if (X_WG.matrix() != object->X_WG.matrix() || scale != object->scale) ++scene_->revision_;
  object->X_WG = X_WG;
  object->scale = scale;
  return 1;
}

std::uint32_t UmqSession::SetColor() {
  if (Short(20, "set color")) return 0;
  UnityObject* object = Target("set color");
  if (!object) return 0;
  std::array<float, 4> rgba;
  for (int i = 0; i < 4; ++i) {
    rgba[i] = LoadF32(head_.data() + 4 + 4 * i);
    if (!std::isfinite(rgba[i]))
      return Refuse("non_finite", "set color: value " + std::to_string(i) + " not finite");
  }
  if (rgba != object->rgba) ++scene_->revision_;
  object->rgba = rgba;
  return 1;
}

std::uint32_t UmqSession::SetText() {
  if (Short(24, "set text")) return 0;
  UnityObject* object = Target("set text");
  if (!object) return 0;
  if (object->kind != ObjectKind::kText)
    return Refuse("unknown_key", "set text: object is not a text object");
  std::array<float, 5> f;  // font size, r, g, b, a
  for (int i = 0; i < 5; ++i) {
    f[i] = LoadF32(head_.data() + 4 + 4 * i);
    if (!std::isfinite(f[i]))
      return Refuse("non_finite", "set text: value " + std::to_string(i) + " not finite");
  }
  const std::array<float, 4> rgba{f[1], f[2], f[3], f[4]};
  if (rgba != object->rgba) ++scene_->revision_;
  object->rgba = rgba;
  return 1;
}

std::uint32_t UmqSession::Execute(std::uint32_t id) {
  UnityScene& s = *scene_;
  switch (id) {
    case umq::kCreatePrimitive: {
      if (Short(4, "create primitive")) return 0;
      const std::uint32_t type = LoadU32(head_.data());
      return CreateObject(type <= 4 ? static_cast<ObjectKind>(type) : ObjectKind::kQuad);
    }
    case umq::kSetActive: {
      if (Short(8, "set active")) return 0;
      UnityObject* object = Target("set active");
      if (!object) return 0;
      const bool active = LoadU32(head_.data() + 4) != 0;
      if (active != object->active) ++s.revision_;
      object->active = active;
      return 1;
    }
    case umq::kSetWorldTransform:
    case umq::kSetLocalTransform:  // the plugin's object stands at Unity's origin
      return SetTransform();
    case umq::kSetColor:
      return SetColor();
    case umq::kSetTexture:
      if (Short(4, "set texture")) return 0;
      return Target("set texture") ? 1 : 0;
    case umq::kCreateText:
      return CreateObject(ObjectKind::kText);
    case umq::kSetText:
      return SetText();
    case umq::kSay:
      return 1;
    case umq::kRemove: {
      if (Short(4, "remove")) return 0;
      const std::int32_t key = use_last_ ? last_key_ : static_cast<std::int32_t>(LoadU32(head_.data()));
      if (s.objects_.erase(key) == 0) return Refuse("unknown_key", "remove: no object " + KeyText(key));
      ++s.revision_;
      return 1;
    }
    case umq::kRemoveAll:
      if (!s.objects_.empty()) ++s.revision_;
      s.objects_.clear();
      return 1;
    case umq::kBeginDisplayList:
      in_display_list_ = true;
      return 1;
    case umq::kEndDisplayList:
      in_display_list_ = false;
      return 1;
    case umq::kSetTargetMode:
      if (Short(4, "set target mode")) return 0;
      use_last_ = LoadU32(head_.data()) != 0;
      return 1;
    case umq::kDebugTryLockPv:
      ++s.pv_locks_;
      return 1;
    case umq::kDebugUnlockPv:
      return s.pv_locks_ > 0 ? (--s.pv_locks_, 1) : 0;
    case umq::kDebugTryLockEv:
      ++s.ev_locks_;
      return 1;
    case umq::kDebugUnlockEv:
      return s.ev_locks_ > 0 ? (--s.ev_locks_, 1) : 0;
    case umq::kDebugMessage: {
      const std::size_t n = std::min<std::size_t>(size_, kMaxDebugMessageBytes);
      s.last_debug_message_ = EscapeText(std::string(reinterpret_cast<const char*>(head_.data()), n));
      return 1;
    }
    case umq::kDisconnect:
      use_last_ = false;
      last_key_ = 0;
      in_display_list_ = false;
      return umq::kDisconnect;
    default:
      Refuse("unknown_command",
             "command id " + std::to_string(id) + " (" + std::to_string(size_) + " bytes)");
      return 0;
  }
}

orbed::hologram_scene_t HologramSceneMessage(const UnityScene& scene, std::int64_t utime) {
  orbed::hologram_scene_t msg{};
  msg.utime = utime;
  msg.revision = scene.revision();
  msg.num_holograms = static_cast<std::int32_t>(scene.objects().size());
  for (const auto& [key, object] : scene.objects()) {
    msg.id.push_back(key);
    msg.kind.push_back(static_cast<std::int8_t>(object.kind));
    msg.X_WG.push_back(ToPose(object.X_WG));
    msg.scale.push_back({object.scale.x(), object.scale.y(), object.scale.z()});
    msg.rgba.push_back({object.rgba[0], object.rgba[1], object.rgba[2], object.rgba[3]});
    msg.active.push_back(object.active);
  }
  return msg;
}

}  // namespace orbed::hl2ss
