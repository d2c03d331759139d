#pragma once
/// @file
/// A z-buffered software rasteriser for the testbed's cameras (the headset's, the fixed monitor's): renders a
/// tessellated scene (Mesh, in W) from a camera at X_WC with pinhole geometry::Intrinsics into an 8-bit BGR
/// cv::Mat, flat Lambert-shaded (ambient + a key light fixed in W + a headlight at the camera), optionally
/// with a depth image and a body-id image. OpenCV is used only for the image containers and JPEG coding.
///
/// Conventions (camera_model.h): C has z forward along the principal ray, x right, y down; pixel
/// (u, v) = K (x/z, y/z, 1); pixel centres are at integers and a pixel is covered when its centre
/// lies inside a triangle (half-open edges, so shared edges are drawn once). Depth is the z_C
/// coordinate [m]; triangles are clipped at z_C = near_m; back faces (seen from C) are culled; a
/// triangle with a non-finite vertex or normal in C (float overflow of far-off geometry) is skipped.
/// The z-test is on 1/z_C, which is affine in (u, v) and so interpolates exactly.
///
/// Overlay (the hologram look): RenderOverlay() draws a mesh (the virtual robot) semi-transparently
/// over an existing image with bright silhouette and link-boundary edges, z-buffered only against
/// itself: like a hologram on a see-through display, it is never hidden by real objects.
///
/// Threading: a Renderer owns scratch buffers; use one per thread. Not re-entrant.

#include <cstdint>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "geometry/camera_model.h"
#include "render/scene_geometry.h"

namespace orbed::render {

struct RenderOptions {
  ColorBgr background_top{72, 66, 62};  ///< vertical gradient behind everything (walls)
  ColorBgr background_bottom{120, 112, 104};
  Eigen::Vector3d light_toward_W{0.35, -0.45, 1.0};  ///< direction toward the key light (any length)
  float ambient{0.28f};
  float key_light{0.42f};
  float headlight{0.38f};
  double near_m{0.02};  ///< near clipping plane z_C [m]
  bool cull_back_faces{true};
};

struct OverlayStyle {
  float face_alpha{0.55f};  ///< opacity of the hologram's faces, 0..1
  bool draw_edges{true};    ///< outline silhouettes and link boundaries
  ColorBgr edge_color{255, 255, 210};
  float edge_alpha{0.9f};
};

class Renderer {
 public:
  explicit Renderer(const geometry::Intrinsics& intrinsics, const RenderOptions& options = {});

  const geometry::Intrinsics& intrinsics() const { return intrinsics_; }
  const RenderOptions& options() const { return options_; }

  /// Renders `mesh` seen from X_WC into `bgr` (CV_8UC3, (re)allocated to the intrinsics' size and
  /// fully overwritten). `depth_m` (CV_32F, z_C [m], 0 where no surface) and `body_id` (CV_32S,
  /// Mesh::Triangle::body, -1 where no surface) are written when not null.
  void Render(const Mesh& mesh, const Eigen::Isometry3d& X_WC, cv::Mat* bgr, cv::Mat* depth_m = nullptr,
              cv::Mat* body_id = nullptr);

  /// Draws `mesh` seen from X_WC over `bgr` (CV_8UC3 of the intrinsics' size, modified in place) in
  /// the hologram style. `body_id`, when not null, receives the overlay's ids (CV_32S, -1 elsewhere).
  /// Throws std::invalid_argument if `bgr` has the wrong type or size.
  void RenderOverlay(const Mesh& mesh, const Eigen::Isometry3d& X_WC, const OverlayStyle& style, cv::Mat* bgr,
                     cv::Mat* body_id = nullptr);

  /// Triangles rasterised by the last call (after culling and clipping).
  int last_triangle_count() const { return last_triangles_; }

 private:
  struct Target;
  template <bool kWriteIds>
  void Draw(const Mesh& mesh, const Eigen::Isometry3d& X_WC, Target* target);
  template <bool kWriteIds>
  void FillTriangle(const double (*uvw)[3], const std::uint8_t* bgr, int body, Target* target);

  geometry::Intrinsics intrinsics_;
  RenderOptions options_;
  Eigen::Vector3f light_W_;
  cv::Mat background_;   // cached gradient, CV_8UC3
  cv::Mat inv_depth_;    // 1/z_C [1/m], 0 = empty, CV_32F
  cv::Mat ids_;          // CV_32S scratch for the overlay
  cv::Mat overlay_bgr_;  // CV_8UC3 scratch for the overlay
  std::vector<Eigen::Vector3f> p_C_;
  int last_triangles_{0};
  // Bounding box of the pixels written by the last Draw() (inclusive), for the overlay blend.
  int min_x_{0}, max_x_{-1}, min_y_{0}, max_y_{-1};
};

/// JPEG-encodes a BGR (or gray) image with cv::imencode; quality 0..100. Returns false on failure.
bool EncodeJpeg(const cv::Mat& image, int quality, std::vector<std::uint8_t>* bytes);
/// Decodes JPEG bytes to BGR; empty Mat on failure.
cv::Mat DecodeJpeg(const std::vector<std::uint8_t>& bytes);

}  // namespace orbed::render
