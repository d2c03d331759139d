#include "render/renderer.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>

#include <opencv2/imgcodecs.hpp>

namespace orbed::render {

// Where Draw() writes: the colour image, the 1/z buffer and (optionally) the body-id image.
struct Renderer::Target {
  std::uint8_t* bgr{nullptr};
  size_t bgr_step{0};  // bytes per row
  float* inv_z{nullptr};
  size_t z_step{0};  // floats per row
  std::int32_t* ids{nullptr};
  size_t id_step{0};  // ints per row
  int width{0}, height{0};
};

Renderer::Renderer(const geometry::Intrinsics& intrinsics, const RenderOptions& options)
    : intrinsics_(intrinsics), options_(options) {
  if (intrinsics.width_px <= 0 || intrinsics.height_px <= 0 || !(intrinsics.fx_px > 0) ||
      !(intrinsics.fy_px > 0))
    throw std::invalid_argument("Renderer: intrinsics need a positive size and focal lengths");
  light_W_ = options.light_toward_W.normalized().cast<float>();
  const int W = intrinsics.width_px, H = intrinsics.height_px;
  background_.create(H, W, CV_8UC3);
  const ColorBgr& a = options.background_top;
  const ColorBgr& b = options.background_bottom;
  for (int y = 0; y < H; ++y) {
    const double t = H > 1 ? static_cast<double>(y) / (H - 1) : 0.0;
    const cv::Vec3b c(static_cast<std::uint8_t>(std::lround(a.b + t * (b.b - a.b))),
                      static_cast<std::uint8_t>(std::lround(a.g + t * (b.g - a.g))),
                      static_cast<std::uint8_t>(std::lround(a.r + t * (b.r - a.r))));
    background_.row(y).setTo(c);
  }
  inv_depth_ = cv::Mat::zeros(H, W, CV_32F);
  ids_.create(H, W, CV_32S);
  overlay_bgr_.create(H, W, CV_8UC3);
}

template <bool kWriteIds>
void Renderer::FillTriangle(const double (*uvw)[3], const std::uint8_t* color, int body, Target* t) {
  // Sort the three projected vertices by v (row).
  const double* a = uvw[0];
  const double* b = uvw[1];
  const double* c = uvw[2];
  if (a[1] > b[1]) std::swap(a, b);
  if (b[1] > c[1]) std::swap(b, c);
  if (a[1] > b[1]) std::swap(a, b);
  const double area2 = (b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1]);
  if (!(std::abs(area2) > 1e-12)) return;
  // 1/z = A u + B v + Cc over the triangle (exact for a planar face under perspective).
  const double A = ((b[2] - a[2]) * (c[1] - a[1]) - (c[2] - a[2]) * (b[1] - a[1])) / area2;
  const double B = ((b[0] - a[0]) * (c[2] - a[2]) - (c[0] - a[0]) * (b[2] - a[2])) / area2;
  const double Cc = a[2] - A * a[0] - B * a[1];

  // Pixel ranges are clamped in double first, so far-off vertices never overflow an int.
  const double H = t->height, W = t->width;
  const int y_begin = static_cast<int>(std::clamp(std::ceil(a[1]), 0.0, H));
  const int y_end = static_cast<int>(std::clamp(std::ceil(c[1]), 0.0, H));  // exclusive
  if (y_begin >= y_end) return;
  const double inv_ac = 1.0 / (c[1] - a[1]);
  for (int y = y_begin; y < y_end; ++y) {
    const double x_long = a[0] + (y - a[1]) * (c[0] - a[0]) * inv_ac;
    double x_short;
    if (y < b[1]) {
      x_short = a[0] + (y - a[1]) * (b[0] - a[0]) / (b[1] - a[1]);
    } else {
      x_short = b[0] + (y - b[1]) * (c[0] - b[0]) / (c[1] - b[1]);
    }
    const double xl = std::min(x_long, x_short), xr = std::max(x_long, x_short);
    const int x_begin = static_cast<int>(std::clamp(std::ceil(xl), 0.0, W));
    const int x_end = static_cast<int>(std::clamp(std::ceil(xr), 0.0, W));
    if (x_begin >= x_end) continue;
    float* z = t->inv_z + y * t->z_step;
    std::uint8_t* px = t->bgr + y * t->bgr_step;
    std::int32_t* id = kWriteIds ? t->ids + y * t->id_step : nullptr;
    double w = A * x_begin + B * y + Cc;
    for (int x = x_begin; x < x_end; ++x, w += A) {
      const float wf = static_cast<float>(w);
      if (wf > z[x]) {
        z[x] = wf;
        px[3 * x + 0] = color[0];
        px[3 * x + 1] = color[1];
        px[3 * x + 2] = color[2];
        if constexpr (kWriteIds) id[x] = body;
      }
    }
    min_x_ = std::min(min_x_, x_begin);
    max_x_ = std::max(max_x_, x_end - 1);
    min_y_ = std::min(min_y_, y);
    max_y_ = std::max(max_y_, y);
  }
}

template <bool kWriteIds>
void Renderer::Draw(const Mesh& mesh, const Eigen::Isometry3d& X_WC, Target* t) {
  // Clear the 1/z buffer where the previous draw wrote (everything else is still 0).
  if (max_x_ >= min_x_ && max_y_ >= min_y_) {
    inv_depth_(cv::Rect(min_x_, min_y_, max_x_ - min_x_ + 1, max_y_ - min_y_ + 1)).setTo(0.0f);
  }
  min_x_ = t->width;
  max_x_ = -1;
  min_y_ = t->height;
  max_y_ = -1;
  last_triangles_ = 0;

  const Eigen::Isometry3d X_CW = X_WC.inverse();
  const Eigen::Matrix3f R_CW = X_CW.linear().cast<float>();
  const Eigen::Vector3f p_CW = X_CW.translation().cast<float>();
  p_C_.resize(mesh.p_W.size());
  for (size_t i = 0; i < mesh.p_W.size(); ++i) p_C_[i] = R_CW * mesh.p_W[i] + p_CW;

  const double fx = intrinsics_.fx_px, fy = intrinsics_.fy_px;
  const double cx = intrinsics_.cx_px, cy = intrinsics_.cy_px;
  const double near = options_.near_m;
  const float ambient = options_.ambient, key = options_.key_light, head = options_.headlight;

  for (const Mesh::Triangle& tri : mesh.triangles) {
    const Eigen::Vector3f& p0 = p_C_[tri.v[0]];
    const Eigen::Vector3f& p1 = p_C_[tri.v[1]];
    const Eigen::Vector3f& p2 = p_C_[tri.v[2]];
    const Eigen::Vector3f n_C = R_CW * tri.normal_W;
    // Geometry far beyond single precision (a pose from the bus thousands of km off) is not drawn.
    if (!(p0.allFinite() && p1.allFinite() && p2.allFinite() && n_C.allFinite())) continue;
    if (p0.z() < near && p1.z() < near && p2.z() < near) continue;
    const Eigen::Vector3f centroid_C = (p0 + p1 + p2) * (1.0f / 3.0f);
    const float facing = n_C.dot(centroid_C);  // < 0: front face (camera at C's origin)
    if (options_.cull_back_faces && facing >= 0) continue;

    // Flat Lambert shading: ambient + key light fixed in W + headlight from the camera.
    const float centroid_dist = centroid_C.norm();
    const float n_dot_eye = centroid_dist > 0 ? std::abs(facing) / centroid_dist : 1.0f;
    float shade = ambient + key * std::max(0.0f, tri.normal_W.dot(light_W_)) + head * n_dot_eye;
    if (!std::isfinite(shade)) continue;  // finite vertices whose sums overflow (near FLT_MAX)
    shade = std::min(shade, 1.0f);
    const std::uint8_t color[3] = {static_cast<std::uint8_t>(tri.color.b * shade + 0.5f),
                                   static_cast<std::uint8_t>(tri.color.g * shade + 0.5f),
                                   static_cast<std::uint8_t>(tri.color.r * shade + 0.5f)};

    // Clip the triangle against z_C >= near (Sutherland-Hodgman, one plane: <= 4 vertices).
    Eigen::Vector3d poly[4];
    int n = 0;
    const Eigen::Vector3f* in[3] = {&p0, &p1, &p2};
    for (int i = 0; i < 3; ++i) {
      const Eigen::Vector3d P = in[i]->cast<double>();
      const Eigen::Vector3d Q = in[(i + 1) % 3]->cast<double>();
      const bool p_in = P.z() >= near, q_in = Q.z() >= near;
      if (p_in) poly[n++] = P;
      if (p_in != q_in) poly[n++] = P + (Q - P) * ((near - P.z()) / (Q.z() - P.z()));
    }
    if (n < 3) continue;
    double uvw[4][3];
    for (int i = 0; i < n; ++i) {
      const double iz = 1.0 / poly[i].z();
      uvw[i][0] = fx * poly[i].x() * iz + cx;
      uvw[i][1] = fy * poly[i].y() * iz + cy;
      uvw[i][2] = iz;
    }
    ++last_triangles_;
    FillTriangle<kWriteIds>(uvw, color, tri.body, t);
    if (n == 4) {
      const double fan[3][3] = {{uvw[0][0], uvw[0][1], uvw[0][2]},
                                {uvw[2][0], uvw[2][1], uvw[2][2]},
                                {uvw[3][0], uvw[3][1], uvw[3][2]}};
      FillTriangle<kWriteIds>(fan, color, tri.body, t);
    }
  }
}

void Renderer::Render(const Mesh& mesh, const Eigen::Isometry3d& X_WC, cv::Mat* bgr, cv::Mat* depth_m,
                      cv::Mat* body_id) {
  const int W = intrinsics_.width_px, H = intrinsics_.height_px;
  background_.copyTo(*bgr);
  Target t;
  t.bgr = bgr->data;
  t.bgr_step = bgr->step[0];
  t.inv_z = inv_depth_.ptr<float>();
  t.z_step = inv_depth_.step[0] / sizeof(float);
  t.width = W;
  t.height = H;
  if (body_id != nullptr) {
    body_id->create(H, W, CV_32S);
    body_id->setTo(-1);
    t.ids = body_id->ptr<std::int32_t>();
    t.id_step = body_id->step[0] / sizeof(std::int32_t);
    Draw<true>(mesh, X_WC, &t);
  } else {
    Draw<false>(mesh, X_WC, &t);
  }
  if (depth_m != nullptr) {
    depth_m->create(H, W, CV_32F);
    for (int y = 0; y < H; ++y) {
      const float* iz = inv_depth_.ptr<float>(y);
      float* d = depth_m->ptr<float>(y);
      for (int x = 0; x < W; ++x) d[x] = iz[x] > 0 ? 1.0f / iz[x] : 0.0f;
    }
  }
}

void Renderer::RenderOverlay(const Mesh& mesh, const Eigen::Isometry3d& X_WC, const OverlayStyle& style,
                             cv::Mat* bgr, cv::Mat* body_id) {
  const int W = intrinsics_.width_px, H = intrinsics_.height_px;
  if (bgr->type() != CV_8UC3 || bgr->cols != W || bgr->rows != H)
    throw std::invalid_argument("RenderOverlay: image must be CV_8UC3 of the intrinsics' size");
  Target t;
  t.bgr = overlay_bgr_.data;
  t.bgr_step = overlay_bgr_.step[0];
  t.inv_z = inv_depth_.ptr<float>();
  t.z_step = inv_depth_.step[0] / sizeof(float);
  t.ids = ids_.ptr<std::int32_t>();
  t.id_step = ids_.step[0] / sizeof(std::int32_t);
  t.width = W;
  t.height = H;
  Draw<true>(mesh, X_WC, &t);
  if (body_id != nullptr) {
    body_id->create(H, W, CV_32S);
    body_id->setTo(-1);
  }
  if (max_x_ < min_x_) return;

  const int face_a = std::clamp(static_cast<int>(std::lround(style.face_alpha * 256)), 0, 256);
  const int edge_a = std::clamp(static_cast<int>(std::lround(style.edge_alpha * 256)), 0, 256);
  const std::uint8_t edge[3] = {style.edge_color.b, style.edge_color.g, style.edge_color.r};
  for (int y = min_y_; y <= max_y_; ++y) {
    const float* z = inv_depth_.ptr<float>(y);
    const float* z_up = y > 0 ? inv_depth_.ptr<float>(y - 1) : nullptr;
    const float* z_dn = y + 1 < H ? inv_depth_.ptr<float>(y + 1) : nullptr;
    const std::int32_t* id = ids_.ptr<std::int32_t>(y);
    const std::int32_t* id_up = y > 0 ? ids_.ptr<std::int32_t>(y - 1) : nullptr;
    const std::int32_t* id_dn = y + 1 < H ? ids_.ptr<std::int32_t>(y + 1) : nullptr;
    const std::uint8_t* ov = overlay_bgr_.ptr<std::uint8_t>(y);
    std::uint8_t* out = bgr->ptr<std::uint8_t>(y);
    std::int32_t* id_out = body_id ? body_id->ptr<std::int32_t>(y) : nullptr;
    for (int x = min_x_; x <= max_x_; ++x) {
      if (!(z[x] > 0)) continue;
      const std::int32_t me = id[x];
      if (id_out) id_out[x] = me;
      bool is_edge = false;
      if (style.draw_edges) {
        auto differs = [me](const float* zr, const std::int32_t* ir, int xx) {
          return !(zr[xx] > 0) || ir[xx] != me;
        };
        is_edge = (x > 0 && differs(z, id, x - 1)) || (x + 1 < W && differs(z, id, x + 1)) ||
                  (z_up && differs(z_up, id_up, x)) || (z_dn && differs(z_dn, id_dn, x));
      }
      const std::uint8_t* src = is_edge ? edge : ov + 3 * x;
      const int a = is_edge ? edge_a : face_a;
      for (int c = 0; c < 3; ++c)
        out[3 * x + c] = static_cast<std::uint8_t>((out[3 * x + c] * (256 - a) + src[c] * a) >> 8);
    }
  }
}

bool EncodeJpeg(const cv::Mat& image, int quality, std::vector<std::uint8_t>* bytes) {
  const std::vector<int> params = {cv::IMWRITE_JPEG_QUALITY, std::clamp(quality, 0, 100)};
  try {
    return cv::imencode(".jpg", image, *bytes, params);
  } catch (const cv::Exception&) {
    return false;
  }
}

cv::Mat DecodeJpeg(const std::vector<std::uint8_t>& bytes) {
  if (bytes.empty()) return cv::Mat();
  try {
    return cv::imdecode(bytes, cv::IMREAD_COLOR);
  } catch (const cv::Exception&) {
    return cv::Mat();
  }
}

}  // namespace orbed::render
