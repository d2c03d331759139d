// An hl2ss client's holograms in the headset:
//   - TessellateHolograms: Unity's primitives at Unity's sizes, scaled and posed, wound outward
//     (also when mirrored), faces where Unity shows them, inactive and text objects not drawn;
//   - orbed-hmd in-process (memq://, images inline): a sphere placed by the bytes of hl2ss's
//     sample display list (through procs/hl2ss/unity_scene.h) shows in AR_VIEW and over the
//     REFLECTIVE_VIEW frame centred on the pixel where the AR_VIEW's own camera model (its
//     intrinsics and X_WC) projects the sphere's centre; removing it gives back the camera frame
//     byte for byte; a bad HOLOGRAMS is refused and counted, the holograms drawn before kept;
//   - the core keeps a re-sent scene's triangles and forgets holograms 3 s after the last message.
#include "hmd_emulator/holograms.h"

#include <cstring>
#include <map>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>
#include <orbed/image_t.hpp>
#include <orbed/reflective_view_t.hpp>

#include "hmd_emulator/hmd_process.h"
#include "lcmtypes/contract/conversions.h"
#include "procs/hl2ss/unity_scene.h"
#include "render/renderer.h"

namespace orbed::hmd {
namespace {

using HS = orbed::hologram_scene_t;

HS One(std::int8_t kind, const Eigen::Isometry3d& X_WG, const Eigen::Vector3d& scale, bool active = true) {
  HS m{};
  m.num_holograms = 1;
  m.id = {1};
  m.kind = {kind};
  m.X_WG = {ToPose(X_WG)};
  m.scale = {{scale.x(), scale.y(), scale.z()}};
  m.rgba = {{1, 0, 0, 1}};
  m.active = {active};
  return m;
}

// Every triangle's normal points away from `centre` (a convex shape's inside), and is its winding's.
void ExpectOutward(const render::Mesh& mesh, const Eigen::Vector3f& centre) {
  for (const auto& t : mesh.triangles) {
    const Eigen::Vector3f a = mesh.p_W[t.v[0]], b = mesh.p_W[t.v[1]], c = mesh.p_W[t.v[2]];
    EXPECT_GT(t.normal_W.dot((a + b + c) / 3 - centre), 0);
    EXPECT_GT(t.normal_W.dot((b - a).cross(c - a)), 0);
  }
}

TEST(Holograms, UnitysPrimitivesAtUnitysSizes) {
  Eigen::Isometry3d X_WG = Eigen::Isometry3d::Identity();
  X_WG.translation() = Eigen::Vector3d(1, 2, 3);
  X_WG.linear() = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, -1).normalized()).toRotationMatrix();
  const Eigen::Vector3f centre = X_WG.translation().cast<float>();
  // A cube of scale (0.2, 0.4, 0.6): 12 triangles, corners at ±scale/2 along G's axes.
  render::Mesh cube;
  TessellateHolograms(One(HS::KIND_CUBE, X_WG, {0.2, 0.4, 0.6}), {}, &cube);
  ASSERT_EQ(cube.triangles.size(), 12u);
  for (const auto& p_W : cube.p_W) {
    const Eigen::Vector3d p_G = X_WG.inverse() * p_W.cast<double>();
    EXPECT_NEAR(std::abs(p_G.x()), 0.1, 1e-6);
    EXPECT_NEAR(std::abs(p_G.y()), 0.2, 1e-6);
    EXPECT_NEAR(std::abs(p_G.z()), 0.3, 1e-6);
  }
  ExpectOutward(cube, centre);
  EXPECT_EQ(cube.triangles[0].body, kHologramBodyBase);
  EXPECT_EQ(cube.triangles[0].color.r, 255);
  EXPECT_EQ(cube.triangles[0].color.b, 0);
  // A mirrored cube (one negative axis) still winds outward.
  render::Mesh mirrored;
  TessellateHolograms(One(HS::KIND_CUBE, X_WG, {-0.2, 0.4, 0.6}), {}, &mirrored);
  ExpectOutward(mirrored, centre);
  // Sphere: diameter 1 (vertices on the surface); cylinder and capsule: diameter 1, 2 long along y_G.
  for (const std::int8_t kind : {HS::KIND_SPHERE, HS::KIND_CYLINDER, HS::KIND_CAPSULE}) {
    render::Mesh mesh;
    TessellateHolograms(One(kind, X_WG, {1, 1, 1}), {}, &mesh);
    ExpectOutward(mesh, centre);
    double max_y = 0, max_r = 0;
    for (const auto& p_W : mesh.p_W) {
      const Eigen::Vector3d p_G = X_WG.inverse() * p_W.cast<double>();
      max_y = std::max(max_y, std::abs(p_G.y()));
      max_r = std::max(max_r, std::hypot(p_G.x(), p_G.z()));
    }
    EXPECT_NEAR(max_y, kind == HS::KIND_SPHERE ? 0.5 : 1.0, 1e-6) << int{kind};
    EXPECT_NEAR(max_r, 0.5, 1e-6) << int{kind};
  }
  // Plane: 10 m square in x_G z_G facing +y_G; quad: 1 m square in x_G y_G facing +z_G.
  for (const auto& [kind, half, normal_G] :
       {std::tuple{int8_t{HS::KIND_PLANE}, 5.0, Eigen::Vector3d::UnitY().eval()},
        std::tuple{int8_t{HS::KIND_QUAD}, 0.5, Eigen::Vector3d::UnitZ().eval()}}) {
    render::Mesh mesh;
    TessellateHolograms(One(kind, X_WG, {1, 1, 1}), {}, &mesh);
    ASSERT_EQ(mesh.triangles.size(), 2u);
    for (const auto& t : mesh.triangles)
      EXPECT_LT((t.normal_W.cast<double>() - X_WG.linear() * normal_G).norm(), 1e-6);
    for (const auto& p_W : mesh.p_W) {
      const Eigen::Vector3d p_G = X_WG.inverse() * p_W.cast<double>();
      EXPECT_NEAR(p_G.dot(normal_G), 0, 1e-6);
      EXPECT_NEAR(p_G.cwiseAbs().maxCoeff(), half, 1e-6);
    }
  }
  // Not drawn: an inactive hologram, a text object.
  render::Mesh none;
  TessellateHolograms(One(HS::KIND_CUBE, X_WG, {1, 1, 1}, false), {}, &none);
  TessellateHolograms(One(HS::KIND_TEXT, X_WG, {1, 1, 1}), {}, &none);
  EXPECT_TRUE(none.triangles.empty());
}

// The client's command buffer (hl2ss_rus.py's layouts).
struct Commands {
  std::vector<std::uint8_t> bytes;
  void U32(std::uint32_t v) {
    for (int i = 0; i < 4; ++i) bytes.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
  }
  void F32(float f) {
    std::uint32_t b;
    std::memcpy(&b, &f, 4);
    U32(b);
  }
  void Add(std::uint32_t id, std::uint32_t size) {
    U32(id);
    U32(size);
  }
};

// hl2ss's sample display list with a red sphere of diameter `d_m` at Unity position p_U.
Commands RedSphere(const Eigen::Vector3d& p_U, float d_m) {
  Commands c;
  c.Add(hl2ss::umq::kBeginDisplayList, 0);
  c.Add(hl2ss::umq::kCreatePrimitive, 4);
  c.U32(0);  // sphere
  c.Add(hl2ss::umq::kSetTargetMode, 4);
  c.U32(1);  // UseLast
  c.Add(hl2ss::umq::kSetWorldTransform, 44);
  c.U32(0);
  for (float f : {static_cast<float>(p_U.x()), static_cast<float>(p_U.y()), static_cast<float>(p_U.z()), 0.f,
                  0.f, 0.f, 1.f, d_m, d_m, d_m})
    c.F32(f);
  c.Add(hl2ss::umq::kSetColor, 20);
  c.U32(0);
  for (float f : {1.f, 0.f, 0.f, 1.f}) c.F32(f);
  c.Add(hl2ss::umq::kSetActive, 8);
  c.U32(0);
  c.U32(1);
  c.Add(hl2ss::umq::kSetTargetMode, 4);
  c.U32(0);
  c.Add(hl2ss::umq::kEndDisplayList, 0);
  return c;
}

template <typename Msg>
void CollectInto(lcm::LCM& lcm, const std::string& channel, std::vector<Msg>* out) {
  lcm.subscribeFunction(
      channel,
      +[](const lcm::ReceiveBuffer*, const std::string&, const Msg* m, std::vector<Msg>* o) {
        o->push_back(*m);
      },
      out);
}

void Drain(lcm::LCM& lcm) {
  while (lcm.handleTimeout(0) > 0) {
  }
}

// The centroid of the pixels where `a` and `b` differ by more than 40 in some channel, and their count.
std::pair<Eigen::Vector2d, int> Changed(const cv::Mat& a, const cv::Mat& b) {
  cv::Mat diff, mask;
  cv::absdiff(a, b, diff);
  cv::Mat channels[3];
  cv::split(diff, channels);
  mask = cv::max(channels[0], cv::max(channels[1], channels[2])) > 40;
  const cv::Moments m = cv::moments(mask, true);
  if (m.m00 == 0) return {Eigen::Vector2d::Zero(), 0};
  return {Eigen::Vector2d(m.m10 / m.m00, m.m01 / m.m00), cv::countNonZero(mask)};
}

TEST(Holograms, ASpherePlacedByAClientShowsWhereTheCameraModelProjectsIt) {
  CommonFlags flags("orbed-hmd");
  flags.lcm_url = "memq://";
  flags.log_level = "warn";
  HmdOptions options;
  options.threaded = false;  // images inline: deterministic
  options.displays = 1;
  HmdProcess hmd(flags, options);
  lcm::LCM& lcm = hmd.process().lcm();
  std::vector<orbed::hmd_pose_t> poses;
  std::vector<orbed::image_t> camera, ar;
  std::vector<orbed::reflective_view_t> reflective;
  CollectInto(lcm, "HMD_POSE", &poses);
  CollectInto(lcm, "HMD_CAMERA", &camera);
  CollectInto(lcm, "AR_VIEW", &ar);
  CollectInto(lcm, "REFLECTIVE_VIEW", &reflective);
  // No robot on the bus: no virtual robot in the overlay, the client's sphere alone.
  hmd.PublishPose();
  hmd.RequestCamera();  // display 0 captures this frame
  Drain(lcm);
  ASSERT_EQ(poses.size(), 1u);
  ASSERT_EQ(camera.size(), 1u);

  // A sphere of diameter 0.25 m, 2 m ahead of the (estimated) camera and a little off its axis.
  const Eigen::Isometry3d X_WC = FromPose(poses[0].X_WC);
  const Eigen::Vector3d p_W = X_WC * Eigen::Vector3d(0.15, -0.1, 2.0);
  const Eigen::Vector3d p_U(p_W.x(), p_W.z(), p_W.y());  // frames.h: p_W = (x_U, z_U, y_U)
  hl2ss::UnityScene scene;
  hl2ss::UmqSession session(&scene);
  std::vector<std::uint8_t> reply;
  const Commands place = RedSphere(p_U, 0.25f);
  ASSERT_TRUE(session.Consume(place.bytes.data(), place.bytes.size(), &reply));
  ASSERT_EQ(reply.size(), 4u * 8);
  const orbed::hologram_scene_t placed = hl2ss::HologramSceneMessage(scene, NowMicros());
  lcm.publish("HOLOGRAMS", &placed);
  Drain(lcm);
  hmd.RequestArView();
  hmd.RequestReflective();
  Drain(lcm);
  ASSERT_EQ(ar.size(), 1u);
  ASSERT_EQ(reflective.size(), 1u);

  // The AR view's own camera model: p_C = X_WC⁻¹ p_W, (u, v) = (fx x/z + cx, fy y/z + cy).
  const orbed::image_t& view = ar[0];
  const Eigen::Vector3d p_C = FromPose(view.X_WC).inverse() * p_W;
  const Eigen::Vector2d uv(view.fx_px * p_C.x() / p_C.z() + view.cx_px,
                           view.fy_px * p_C.y() / p_C.z() + view.cy_px);
  const cv::Mat frame = render::DecodeJpeg(camera[0].data);
  const cv::Mat with_sphere = render::DecodeJpeg(view.data);
  const auto [centre, pixels] = Changed(with_sphere, frame);
  // Radius ≈ f r / z = 1545 · 0.125 / 2 ≈ 97 px: about 29 000 pixels.
  EXPECT_GT(pixels, 20000);
  EXPECT_LT(pixels, 36000);
  EXPECT_LT((centre - uv).norm(), 2.0)
      << "drawn at " << centre.transpose() << ", projected " << uv.transpose();
  const cv::Vec3b at = with_sphere.at<cv::Vec3b>(static_cast<int>(uv.y()), static_cast<int>(uv.x()));
  EXPECT_GT(int{at[2]} - int{at[1]}, 60) << "red over the room: BGR " << at;  // red, not the grey room
  // Over the reflective display's frame (captured at this very pose) in the same place.
  const cv::Mat mirror = render::DecodeJpeg(reflective[0].image.data);
  const auto [mirror_centre, mirror_pixels] = Changed(mirror, frame);
  EXPECT_GT(mirror_pixels, 20000);
  EXPECT_LT((mirror_centre - uv).norm(), 2.0);

  // A bad HOLOGRAMS is refused whole and counted; what was drawn stays.
  orbed::hologram_scene_t bad = placed;
  bad.kind[0] = 9;
  lcm.publish("HOLOGRAMS", &bad);
  Drain(lcm);
  EXPECT_EQ(hmd.process().rejections().counts().at("HOLOGRAMS/kind"), 1);
  hmd.RequestArView();
  Drain(lcm);
  ASSERT_EQ(ar.size(), 2u);
  EXPECT_EQ(ar[1].data, ar[0].data);

  // The client removes it: AR_VIEW is the camera frame again, byte for byte.
  Commands remove;
  remove.Add(hl2ss::umq::kRemove, 4);
  remove.U32(scene.objects().begin()->first);
  ASSERT_TRUE(session.Consume(remove.bytes.data(), remove.bytes.size(), &reply));
  EXPECT_TRUE(scene.objects().empty());
  const orbed::hologram_scene_t removed = hl2ss::HologramSceneMessage(scene, NowMicros());
  lcm.publish("HOLOGRAMS", &removed);
  Drain(lcm);
  hmd.RequestArView();
  Drain(lcm);
  ASSERT_EQ(ar.size(), 3u);
  EXPECT_EQ(ar[2].data, camera[0].data);
}

TEST(Holograms, TheCoreKeepsAResentSceneAndForgetsAStaleOne) {
  Headset headset(ResolveHmdOptions(HmdOptions{}), 1, 0);
  EXPECT_EQ(headset.Holograms(0), nullptr);
  HS scene = One(HS::KIND_CUBE, Eigen::Isometry3d::Identity(), {1, 1, 1});
  scene.utime = 100;
  headset.OnHolograms(scene, 10.0);
  const auto first = headset.Holograms(10.0);
  ASSERT_NE(first, nullptr);
  EXPECT_EQ(first->triangles.size(), 12u);
  scene.utime = 200;  // re-sent: the same triangles
  headset.OnHolograms(scene, 11.0);
  EXPECT_EQ(headset.Holograms(11.0), first);
  EXPECT_NE(headset.Holograms(13.9), nullptr);
  EXPECT_EQ(headset.Holograms(14.1), nullptr);  // 3 s after the last
  scene.revision = 1;
  scene.active[0] = false;  // another scene: new (here no) triangles
  headset.OnHolograms(scene, 12.0);
  EXPECT_NE(headset.Holograms(12.0), first);
  EXPECT_TRUE(headset.Holograms(12.0)->triangles.empty());
  EXPECT_EQ(headset.Inputs(12.0).holograms, headset.Holograms(12.0));
}

}  // namespace
}  // namespace orbed::hmd
