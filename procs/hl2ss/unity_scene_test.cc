// The remote Unity scene from hand-packed bytes (the layouts of hl2ss_rus.py's command_buffer):
//   - hl2ss's own sample sequence (a display list that creates a cube, targets it with UseLast, sets
//     its transform, colour and visibility) answers what the plugin answers, whatever the split of
//     the bytes, and leaves the cube at the pose frames.h gives (worked out by hand below);
//   - every refusal answers 0, changes nothing, is counted under its key, and keeps the stream in step;
//   - a command over the size cap closes the connection before its data is read;
//   - objects outlive a disconnect, the target mode does not;
//   - the HOLOGRAMS message holds the state and passes the bounded wire check.
#include "procs/hl2ss/unity_scene.h"

#include <cmath>
#include <cstring>
#include <limits>
#include <map>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "lcmtypes/bounded_decode.h"
#include "lcmtypes/contract/conversions.h"

namespace orbed::hl2ss {
namespace {

using Bytes = std::vector<std::uint8_t>;

void PutU32(std::uint32_t v, Bytes* b) {
  for (int i = 0; i < 4; ++i) b->push_back(static_cast<std::uint8_t>(v >> (8 * i)));
}
void PutF32(float f, Bytes* b) {
  std::uint32_t bits;
  std::memcpy(&bits, &f, 4);
  PutU32(bits, b);
}

// One command: id, size, data (umq_command_buffer.add).
struct Buffer {
  Bytes bytes;
  int count = 0;
  void Add(std::uint32_t id, const Bytes& data) {
    PutU32(id, &bytes);
    PutU32(static_cast<std::uint32_t>(data.size()), &bytes);
    bytes.insert(bytes.end(), data.begin(), data.end());
    ++count;
  }
  void Create(std::uint32_t type) { Add(umq::kCreatePrimitive, U32s({type})); }
  void TargetMode(std::uint32_t mode) { Add(umq::kSetTargetMode, U32s({mode})); }
  void Active(std::uint32_t key, std::uint32_t state) { Add(umq::kSetActive, U32s({key, state})); }
  void Transform(std::uint32_t key, const std::vector<float>& ten) {
    Add(umq::kSetWorldTransform, KeyFloats(key, ten));
  }
  void Color(std::uint32_t key, const std::vector<float>& rgba) { Add(umq::kSetColor, KeyFloats(key, rgba)); }
  void Remove(std::uint32_t key) { Add(umq::kRemove, U32s({key})); }
  static Bytes U32s(const std::vector<std::uint32_t>& v) {
    Bytes b;
    for (std::uint32_t x : v) PutU32(x, &b);
    return b;
  }
  static Bytes KeyFloats(std::uint32_t key, const std::vector<float>& f) {
    Bytes b;
    PutU32(key, &b);
    for (float x : f) PutF32(x, &b);
    return b;
  }
};

std::vector<std::uint32_t> Answers(const Bytes& reply) {
  EXPECT_EQ(reply.size() % 4, 0u);
  std::vector<std::uint32_t> out;
  for (std::size_t i = 0; i + 4 <= reply.size(); i += 4) {
    out.push_back(reply[i] | reply[i + 1] << 8 | reply[i + 2] << 16 |
                  static_cast<std::uint32_t>(reply[i + 3]) << 24);
  }
  return out;
}

// Feeds `bytes` in pieces of `piece` bytes; returns the answers.
std::vector<std::uint32_t> Feed(UmqSession* session, const Bytes& bytes, std::size_t piece) {
  Bytes reply;
  for (std::size_t i = 0; i < bytes.size(); i += piece) {
    EXPECT_TRUE(session->Consume(bytes.data() + i, std::min(piece, bytes.size() - i), &reply));
  }
  return Answers(reply);
}

std::map<std::string, int> Keys(UmqSession* session) {
  std::map<std::string, int> n;
  for (const Refusal& r : session->TakeRefusals()) ++n[r.key];
  return n;
}

// hl2ss's sample: begin, remove all, create a cube, UseLast, transform, colour, active, UseID, end.
Buffer CubeSample() {
  const float s45 = static_cast<float>(std::sqrt(0.5));
  Buffer b;
  b.Add(umq::kBeginDisplayList, {});
  b.Add(umq::kRemoveAll, {});
  b.Create(3);
  b.TargetMode(1);
  // At Unity (1, 2, 3), turned +90 deg about Unity's y (x, y, z, w = 0, s45, 0, s45), scale (0.2, 0.3, 0.4).
  b.Transform(0, {1, 2, 3, 0, s45, 0, s45, 0.2f, 0.3f, 0.4f});
  b.Color(0, {1, 0, 0, 0.5f});
  b.Active(0, 1);
  b.TargetMode(0);
  b.Add(umq::kEndDisplayList, {});
  return b;
}

TEST(UnityScene, TheSampleSequenceAnswersAsThePluginWhateverTheSplit) {
  const Buffer sample = CubeSample();
  for (std::size_t piece : {std::size_t{1}, std::size_t{3}, std::size_t{7}, sample.bytes.size()}) {
    UnityScene scene;
    UmqSession session(&scene);
    const std::vector<std::uint32_t> answers = Feed(&session, sample.bytes, piece);
    ASSERT_EQ(answers.size(), 9u) << piece;
    EXPECT_EQ(answers, (std::vector<std::uint32_t>{1, 1, 1, 1, 1, 1, 1, 1, 1})) << piece;  // key 1 third
    EXPECT_TRUE(Keys(&session).empty());
    EXPECT_EQ(session.commands(), 9);
    EXPECT_FALSE(session.in_display_list());
    ASSERT_EQ(scene.objects().size(), 1u);
    const UnityObject& cube = scene.objects().at(1);
    EXPECT_EQ(cube.kind, ObjectKind::kCube);
    EXPECT_TRUE(cube.active);
    // p_U = (1, 2, 3): p_D = (1, 2, -3), p_W = R_WD p_D = (1, 3, 2) (x, z_U, y_U).
    EXPECT_LT((cube.X_WG.translation() - Eigen::Vector3d(1, 3, 2)).norm(), 1e-6);
    // R_U (about y by +90 deg) maps x_U to -z_U and z_U to x_U. So G's axes in W: x_G = x_U-local
    // → -z_U → -y_W; y_G → y_U → z_W; z_G = -z_U-local → -x_U → -x_W.
    Eigen::Matrix3d R_WG_expected;
    R_WG_expected.col(0) = -Eigen::Vector3d::UnitY();
    R_WG_expected.col(1) = Eigen::Vector3d::UnitZ();
    R_WG_expected.col(2) = -Eigen::Vector3d::UnitX();
    EXPECT_LT((cube.X_WG.linear() - R_WG_expected).norm(), 1e-6);
    EXPECT_LT((cube.scale - Eigen::Vector3d(0.2, 0.3, 0.4)).norm(), 1e-6);
    EXPECT_EQ(cube.rgba, (std::array<float, 4>{1, 0, 0, 0.5f}));
  }
}

// PoseFromUnity against the frames written out directly: Unity's coordinates to W swap y and z
// (P), and G is Unity's local frame with z negated (S): R_WG = P R_U S, p_W = P p_U; R_U from the
// quaternion by the textbook formula (Unity's Quaternion is the usual Hamilton quaternion).
TEST(UnityScene, PoseFromUnityIsTheSwapOfUnitysAxes) {
  Eigen::Matrix3d P;
  P << 1, 0, 0, 0, 0, 1, 0, 1, 0;
  const Eigen::Matrix3d S = Eigen::Vector3d(1, 1, -1).asDiagonal();
  for (const Eigen::Vector4d& q : {Eigen::Vector4d(0.1, -0.7, 0.3, 0.6),
                                   Eigen::Vector4d(0.9, 0.2, -0.1, -0.3), Eigen::Vector4d(0, 0, 0, 2)}) {
    const Eigen::Vector4d u = q.normalized();
    const double x = u[0], y = u[1], z = u[2], w = u[3];
    Eigen::Matrix3d R_U;
    R_U << 1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w),  //
        2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w),     //
        2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y);
    const Eigen::Vector3d p_U(0.4, -1.5, 2.5);
    const Eigen::Isometry3d X_WG = PoseFromUnity(p_U, q);
    EXPECT_LT((X_WG.linear() - P * R_U * S).norm(), 1e-12) << q.transpose();
    EXPECT_LT((X_WG.translation() - P * p_U).norm(), 1e-12);
    EXPECT_NEAR(X_WG.linear().determinant(), 1.0, 1e-12);
  }
}

TEST(UnityScene, KeysCountUpAndUseIdTargetsTheKeyGiven) {
  UnityScene scene;
  UmqSession session(&scene);
  Buffer b;
  b.Create(0);                  // sphere → 1
  b.Create(2);                  // cylinder → 2
  b.Create(77);                 // any other type: a quad (the plugin's default) → 3
  b.Add(umq::kCreateText, {});  // → 4
  b.Active(2, 1);
  b.Active(9, 1);  // no object 9
  EXPECT_EQ(Feed(&session, b.bytes, 5), (std::vector<std::uint32_t>{1, 2, 3, 4, 1, 0}));
  EXPECT_EQ(Keys(&session), (std::map<std::string, int>{{"unknown_key", 1}}));
  EXPECT_EQ(scene.objects().at(1).kind, ObjectKind::kSphere);
  EXPECT_EQ(scene.objects().at(2).kind, ObjectKind::kCylinder);
  EXPECT_EQ(scene.objects().at(3).kind, ObjectKind::kQuad);
  EXPECT_EQ(scene.objects().at(4).kind, ObjectKind::kText);
  EXPECT_FALSE(scene.objects().at(1).active);
  EXPECT_TRUE(scene.objects().at(2).active);
}

TEST(UnityScene, RefusalsAnswerZeroChangeNothingAndKeepTheStreamInStep) {
  UnityScene scene;
  UmqSession session(&scene);
  Feed(&session, CubeSample().bytes, 64);
  const UnityObject before = scene.objects().at(1);
  const std::int64_t revision = scene.revision();
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  Buffer b;
  b.Add(umq::kSetWorldTransform, Buffer::U32s({1, 0, 0}));      // short: 12 of 44 bytes
  b.Transform(1, {0, 0, 0, 0, 0, 0, 1, 1, nan, 1});             // non_finite
  b.Transform(1, {2e4f, 0, 0, 0, 0, 0, 1, 1, 1, 1});            // range: 20 km
  b.Transform(1, {0, 0, 0, 0, 0, 0, 1, 1, 1, 5e3f});            // range: scale
  b.Transform(1, {0, 0, 0, 0, 0, 0, 0, 1, 1, 1});               // range: zero rotation
  b.Color(1, {inf, 0, 0, 1});                                   // non_finite
  b.Add(15, Bytes(100, 0xAB));                                  // load mesh: unknown here
  b.Add(12345, {});                                             // unknown
  b.Add(umq::kSetText, Buffer::KeyFloats(1, {1, 1, 1, 1, 1}));  // a cube is no text object
  b.Remove(42);                                                 // unknown_key
  b.Add(umq::kSetColor, Buffer::U32s({1}));                     // short
  b.Active(1, 0);                                               // in step: accepted
  EXPECT_EQ(Feed(&session, b.bytes, 13), (std::vector<std::uint32_t>{0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 1}));
  EXPECT_EQ(Keys(&session),
            (std::map<std::string, int>{
                {"short", 2}, {"non_finite", 2}, {"range", 3}, {"unknown_command", 2}, {"unknown_key", 2}}));
  const UnityObject& after = scene.objects().at(1);
  EXPECT_EQ(after.X_WG.matrix(), before.X_WG.matrix());
  EXPECT_EQ(after.scale, before.scale);
  EXPECT_EQ(after.rgba, before.rgba);
  EXPECT_FALSE(after.active);
  EXPECT_EQ(scene.revision(), revision + 1);  // only the last command changed the scene
}

TEST(UnityScene, TheObjectCapRefusesACreate) {
  UnitySceneLimits limits;
  limits.max_objects = 2;
  UnityScene scene(limits);
  UmqSession session(&scene);
  Buffer b;
  for (int i = 0; i < 3; ++i) b.Create(3);
  b.Remove(1);
  b.Create(3);
  EXPECT_EQ(Feed(&session, b.bytes, 100), (std::vector<std::uint32_t>{1, 2, 0, 1, 3}));
  EXPECT_EQ(Keys(&session), (std::map<std::string, int>{{"objects", 1}}));
  EXPECT_EQ(scene.objects().size(), 2u);
  EXPECT_THROW(UnityScene(UnitySceneLimits{0}), std::invalid_argument);
}

TEST(UnityScene, ACommandOverTheSizeCapClosesBeforeItsDataIsRead) {
  UnitySceneLimits limits;
  limits.max_command_bytes = 1000;
  UnityScene scene(limits);
  UmqSession session(&scene);
  Buffer b;
  b.Add(umq::kSetTexture, Buffer::U32s({0}));  // answered: 0, no object 0
  Bytes bytes = b.bytes;
  PutU32(umq::kSetTexture, &bytes);
  PutU32(0xFFFFFFF0u, &bytes);  // a 4 GB texture
  bytes.resize(bytes.size() + 16, 0);
  Bytes reply;
  EXPECT_FALSE(session.Consume(bytes.data(), bytes.size(), &reply));
  EXPECT_EQ(Answers(reply), (std::vector<std::uint32_t>{0}));  // what came before is answered
  EXPECT_EQ(Keys(&session), (std::map<std::string, int>{{"unknown_key", 1}, {"size", 1}}));
  EXPECT_FALSE(session.Consume(bytes.data(), 8, &reply));
  EXPECT_EQ(reply.size(), 4u);
  // Within the cap a texture's bytes are counted off, not kept: answered once complete.
  UmqSession other(&scene);
  Buffer t;
  t.Create(5);
  Bytes texture = Buffer::U32s({1});
  texture.resize(1000, 0x5A);
  t.Add(umq::kSetTexture, texture);
  EXPECT_EQ(Feed(&other, t.bytes, 7), (std::vector<std::uint32_t>{1, 1}));
}

TEST(UnityScene, ObjectsOutliveADisconnectTheTargetModeDoesNot) {
  UnityScene scene;
  UmqSession first(&scene);
  Buffer b;
  b.Create(1);
  b.TargetMode(1);
  b.Add(umq::kBeginDisplayList, {});
  Feed(&first, b.bytes, 4);
  EXPECT_TRUE(first.in_display_list());
  first.OnDisconnect();
  EXPECT_FALSE(first.in_display_list());
  UmqSession second(&scene);
  Buffer c;
  c.Active(0, 1);  // UseID again: no object 0
  c.Active(1, 1);
  c.Add(umq::kDisconnect, {});
  c.Add(umq::kRemoveAll, {});
  EXPECT_EQ(Feed(&second, c.bytes, 3), (std::vector<std::uint32_t>{0, 1, 0xFFFFFFFFu, 1}));
  EXPECT_TRUE(scene.objects().empty());
}

TEST(UnityScene, DebugCommandsAnswerAsThePlugin) {
  UnityScene scene;
  UmqSession session(&scene);
  Buffer b;
  b.Add(umq::kDebugUnlockPv, {});
  b.Add(umq::kDebugTryLockPv, {});
  b.Add(umq::kDebugUnlockPv, {});
  b.Add(umq::kDebugTryLockEv, {});
  b.Add(umq::kDebugUnlockEv, {});
  const std::string text = "hello\n";
  b.Add(umq::kDebugMessage, Bytes(text.begin(), text.end()));
  b.Add(umq::kSay, Bytes(text.begin(), text.end()));
  EXPECT_EQ(Feed(&session, b.bytes, 2), (std::vector<std::uint32_t>{0, 1, 1, 1, 1, 1, 1}));
  EXPECT_EQ(scene.last_debug_message(), "hello\\x0a");
}

TEST(UnityScene, TheHologramsMessageHoldsTheStateAndPassesTheWireCheck) {
  UnityScene scene;
  UmqSession session(&scene);
  Feed(&session, CubeSample().bytes, 1000);
  Buffer b;
  b.Create(0);
  Feed(&session, b.bytes, 1000);
  const orbed::hologram_scene_t msg = HologramSceneMessage(scene, 1'700'000'000'000'000);
  EXPECT_EQ(msg.utime, 1'700'000'000'000'000);
  EXPECT_EQ(msg.revision, scene.revision());
  ASSERT_EQ(msg.num_holograms, 2);
  EXPECT_EQ(msg.id, (std::vector<std::int32_t>{1, 2}));
  EXPECT_EQ(msg.kind, (std::vector<std::int8_t>{3, 0}));
  EXPECT_EQ(msg.active, (std::vector<std::int8_t>{1, 0}));
  EXPECT_LT((FromPose(msg.X_WG[0]).translation() - Eigen::Vector3d(1, 3, 2)).norm(), 1e-6);
  EXPECT_NEAR(msg.scale[0][2], 0.4, 1e-6);
  EXPECT_FLOAT_EQ(msg.rgba[0][3], 0.5f);
  EXPECT_EQ(msg.rgba[1], (std::vector<float>{1, 1, 1, 1}));
  std::vector<std::uint8_t> bytes(msg.getEncodedSize());
  ASSERT_EQ(msg.encode(bytes.data(), 0, static_cast<int>(bytes.size())), static_cast<int>(bytes.size()));
  orbed::hologram_scene_t back;
  EXPECT_TRUE(DecodeBounded(bytes.data(), bytes.size(), &back).ok());
  EXPECT_EQ(back.id, msg.id);
}

}  // namespace
}  // namespace orbed::hl2ss
