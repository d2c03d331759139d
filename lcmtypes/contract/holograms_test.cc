// HOLOGRAMS' one check: a valid scene passes, each rule refuses by its key.
#include "lcmtypes/contract/holograms.h"

#include <cmath>
#include <limits>

#include <gtest/gtest.h>

namespace orbed {
namespace {

orbed::hologram_scene_t TwoHolograms() {
  orbed::hologram_scene_t m{};
  m.revision = 3;
  m.num_holograms = 2;
  m.id = {1, 7};
  m.kind = {+orbed::hologram_scene_t::KIND_CUBE, +orbed::hologram_scene_t::KIND_QUAD};
  m.X_WG.resize(2);
  for (auto& pose : m.X_WG) pose.quaternion_wxyz[0] = 1;
  m.scale = {{1, 1, 1}, {-0.5, 2, 1}};
  m.rgba = {{1, 0, 0, 1}, {0, 1, 0, 0.5f}};
  m.active = {1, 0};
  return m;
}

std::string Key(const orbed::hologram_scene_t& m) {
  const auto refusal = CheckHologramScene(m);
  return refusal ? refusal->key : "";
}

TEST(Holograms, EachRuleRefusesByItsKey) {
  const orbed::hologram_scene_t good = TwoHolograms();
  EXPECT_EQ(Key(good), "");
  orbed::hologram_scene_t empty{};
  EXPECT_EQ(Key(empty), "");
  auto key = [&](auto mutate) {
    orbed::hologram_scene_t m = good;
    mutate(m);
    return Key(m);
  };
  EXPECT_EQ(key([](auto& m) { m.num_holograms = 3; }), "num_holograms");
  EXPECT_EQ(key([](auto& m) { m.rgba.pop_back(); }), "num_holograms");
  EXPECT_EQ(key([](auto& m) { m.num_holograms = -1; }), "num_holograms");
  EXPECT_EQ(key([](auto& m) { m.revision = -1; }), "num_holograms");
  EXPECT_EQ(key([](auto& m) { m.id[1] = 1; }), "id");
  EXPECT_EQ(key([](auto& m) { m.id[0] = 0; }), "id");
  EXPECT_EQ(key([](auto& m) { m.kind[0] = 7; }), "kind");
  EXPECT_EQ(key([](auto& m) { m.kind[0] = -1; }), "kind");
  EXPECT_EQ(key([](auto& m) { m.X_WG[1].quaternion_wxyz[0] = 0.9; }), "pose");
  EXPECT_EQ(key([](auto& m) { m.X_WG[1].position_m[2] = 2e4; }), "pose");
  EXPECT_EQ(key([](auto& m) { m.scale[0][1] = std::nan(""); }), "scale");
  EXPECT_EQ(key([](auto& m) { m.scale[0][1] = -1001; }), "scale");
  EXPECT_EQ(key([](auto& m) { m.rgba[1][3] = std::numeric_limits<float>::infinity(); }), "rgba");
}

}  // namespace
}  // namespace orbed
