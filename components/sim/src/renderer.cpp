// Renderer: geometry pass (set_view) and per-frame shading (shade); see renderer.hpp.
#include "avs/sim/renderer.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "avs/decode/gray_code.hpp"

namespace avs::sim {
namespace {

constexpr float kFullScaleDn = 255.0f;

std::uint64_t splitmix64(std::uint64_t x) {
  x += 0x9E3779B97F4A7C15ull;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}

/// Standard normal quantiles at (i + 0.5) / 4096: noise is a table lookup per pixel.
constexpr int kNoiseTableBits = 12;
const std::array<float, 1 << kNoiseTableBits>& normal_table() {
  static const auto table = [] {
    std::array<float, 1 << kNoiseTableBits> t{};
    for (std::size_t i = 0; i < t.size(); ++i) {
      const double p = (static_cast<double>(i) + 0.5) / static_cast<double>(t.size());
      double lo = -10, hi = 10;  // solve Phi(x) = p by bisection, Phi(x) = erfc(-x/sqrt2)/2
      for (int it = 0; it < 100; ++it) {
        const double mid = 0.5 * (lo + hi);
        (0.5 * std::erfc(-mid / std::sqrt(2.0)) < p ? lo : hi) = mid;
      }
      t[i] = static_cast<float>(0.5 * (lo + hi));
    }
    return t;
  }();
  return table;
}

PinholeView make_view(const decode::LensModel& lens, double near_m) {
  PinholeView view;
  view.width = lens.width;
  view.height = lens.height;
  view.fx_px = static_cast<float>(lens.fx_px);
  view.fy_px = static_cast<float>(lens.fy_px);
  view.cx_px = static_cast<float>(lens.cx_px);
  view.cy_px = static_cast<float>(lens.cy_px);
  view.near_m = static_cast<float>(near_m);
  return view;
}

/// Adds noise and quantises `count` intensities produced by value(i).
template <typename ValueFn>
void quantise_with_noise(std::size_t count, float sigma_dn, std::uint64_t key, ValueFn value,
                         std::uint8_t* out) {
  const auto& table = normal_table();
  constexpr int kShift = 16 - kNoiseTableBits;
  for (std::size_t i = 0; i < count; i += 4) {
    std::uint64_t r = splitmix64(key + i);
    const std::size_t n = std::min<std::size_t>(4, count - i);
    for (std::size_t k = 0; k < n; ++k, r >>= 16) {
      const float v = value(i + k) + sigma_dn * table[(r & 0xFFFF) >> kShift] + 0.5f;
      out[i + k] = static_cast<std::uint8_t>(std::clamp(v, 0.0f, kFullScaleDn));
    }
  }
}

}  // namespace

std::uint64_t frame_noise_key(std::uint64_t frame_index) {
  return splitmix64(frame_index);
}

Renderer::Renderer(RendererConfig config) : config_(std::move(config)) {
  const decode::SensorGeometry& g = config_.geometry;
  if (g.camera.has_distortion() || g.projector.has_distortion()) {
    throw std::invalid_argument(
        "sim::Renderer: lens distortion is not rendered (pinhole only); set k1..k3, p1, p2 to 0");
  }
  if (g.camera.width <= 0 || g.camera.height <= 0 || g.projector.width <= 0 ||
      g.projector.height <= 0) {
    throw std::invalid_argument("sim::Renderer: camera and projector sizes must be positive");
  }
  camera_view_ = make_view(g.camera, config_.near_clip_m);
  projector_view_ = make_view(g.projector, config_.near_clip_m);
  // Only the coded rows matter: the others are dark in both polarities.
  projector_view_.first_row = std::max(0, g.layout.first_row);
  projector_view_.last_row =
      std::min(g.projector.height, g.layout.first_row + g.layout.used_rows());
  R_projector_camera_ = g.R_projector_camera.cast<float>();
  t_projector_camera_m_ = g.t_projector_camera_m.cast<float>();
  projector_centre_camera_m_ = g.projector_centre_camera_m().cast<float>();
  ray_x_.resize(g.camera.width);
  ray_y_.resize(g.camera.height);
  for (int x = 0; x < g.camera.width; ++x)
    ray_x_[x] = static_cast<float>((x - g.camera.cx_px) / g.camera.fx_px);
  for (int y = 0; y < g.camera.height; ++y)
    ray_y_[y] = static_cast<float>((y - g.camera.cy_px) / g.camera.fy_px);
  const std::size_t pixels = static_cast<std::size_t>(g.camera.width) * g.camera.height;
  base_dn_.assign(pixels, 0.0f);
  gain_dn_.assign(pixels, 0.0f);
  gray_.assign(pixels, 0);
  depth_m_.assign(pixels, 0.0f);
  projector_row_.assign(pixels, std::numeric_limits<float>::quiet_NaN());
  object_index_.assign(pixels, -1);
  code_.assign(pixels, -1);
}

void Renderer::set_view(const std::vector<RenderObject>& objects) {
  if (objects.size() > static_cast<std::size_t>(std::numeric_limits<std::int16_t>::max())) {
    throw std::invalid_argument("sim::Renderer: too many objects");
  }
  // 1. Per-triangle data in the camera frame and both depth buffers.
  camera_buffer_.reset(camera_view_.width, camera_view_.height);
  projector_buffer_.reset(projector_view_.width, projector_view_.height);
  normal_camera_.clear();
  triangle_object_.clear();
  for (std::size_t o = 0; o < objects.size(); ++o) {
    const geometry::Mesh& mesh = *objects[o].mesh;
    const Eigen::Isometry3f T = objects[o].T_camera_object.cast<float>();
    scratch_camera_.resize(mesh.vertices.size());
    scratch_projector_.resize(mesh.vertices.size());
    for (std::size_t v = 0; v < mesh.vertices.size(); ++v) {
      scratch_camera_[v] = T * mesh.vertices[v];
      scratch_projector_[v] = R_projector_camera_ * scratch_camera_[v] + t_projector_camera_m_;
    }
    const auto id_offset = static_cast<std::int32_t>(normal_camera_.size());
    for (const Eigen::Vector3i& t : mesh.triangles) {
      const Eigen::Vector3f& a = scratch_camera_[t[0]];
      normal_camera_.push_back(
          (scratch_camera_[t[1]] - a).cross(scratch_camera_[t[2]] - a).normalized());
      triangle_object_.push_back(static_cast<std::int16_t>(o));
    }
    rasterize(camera_view_, scratch_camera_, mesh.triangles, id_offset, config_.cull_back_faces,
              camera_buffer_);
    rasterize(projector_view_, scratch_projector_, mesh.triangles, id_offset,
              config_.cull_back_faces, projector_buffer_);
  }
  // 2. Per camera pixel: surface point, shadow test, shading, code.
  for (int y = 0; y < camera_view_.height; ++y) {
    for (int x = 0; x < camera_view_.width; ++x) compute_pixel(x, y, objects);
  }
}

void Renderer::compute_pixel(int x, int y, const std::vector<RenderObject>& objects) {
  const std::size_t i = static_cast<std::size_t>(y) * camera_view_.width + x;
  const std::int32_t id = camera_buffer_.triangle[i];
  base_dn_[i] = gain_dn_[i] = 0.0f;
  gray_[i] = 0;
  projector_row_[i] = std::numeric_limits<float>::quiet_NaN();
  code_[i] = -1;
  if (id < 0) {
    depth_m_[i] = 0.0f;
    object_index_[i] = -1;
    return;
  }
  const int object = triangle_object_[id];
  const auto albedo = static_cast<float>(objects[object].albedo);
  const float z = 1.0f / camera_buffer_.inv_depth[i];
  const Eigen::Vector3f p_camera(ray_x_[x] * z, ray_y_[y] * z, z);
  depth_m_[i] = z;
  object_index_[i] = static_cast<std::int16_t>(object);
  base_dn_[i] = kFullScaleDn * albedo * static_cast<float>(config_.ambient_level);

  // Lit only if the projector sees this point (projector shadow test) and it faces it.
  Eigen::Vector3f normal = normal_camera_[id];
  if (normal.dot(p_camera) > 0) normal = -normal;  // back face drawn with culling off
  const Eigen::Vector3f to_projector = projector_centre_camera_m_ - p_camera;
  const float distance = to_projector.norm();
  const float shading = normal.dot(to_projector) / distance;
  if (!(shading > 0)) return;
  const Eigen::Vector3f p_projector = R_projector_camera_ * p_camera + t_projector_camera_m_;
  if (p_projector.z() < projector_view_.near_m) return;
  const float u = projector_view_.fx_px * p_projector.x() / p_projector.z() + projector_view_.cx_px;
  const float v = projector_view_.fy_px * p_projector.y() / p_projector.z() + projector_view_.cy_px;
  const int col = static_cast<int>(std::lround(u)), row = static_cast<int>(std::lround(v));
  if (col < 0 || col >= projector_view_.width || row < projector_view_.first_row ||
      row >= projector_view_.last_row) {
    return;
  }
  const std::size_t j = static_cast<std::size_t>(row) * projector_view_.width + col;
  const float w_seen = projector_buffer_.inv_depth[j];
  const bool same_triangle = projector_buffer_.triangle[j] == id;
  if (!same_triangle && w_seen > 0 &&
      p_projector.z() > 1.0f / w_seen + static_cast<float>(config_.shadow_bias_m)) {
    return;  // something nearer to the projector covers this point
  }
  const int code = decode::code_of_row(config_.geometry.layout, row);
  projector_row_[i] = v;
  if (code < 0) return;
  float irradiance = static_cast<float>(config_.projector_level) * shading;
  if (config_.falloff_reference_m > 0) {
    const float r = static_cast<float>(config_.falloff_reference_m) / distance;
    irradiance *= r * r;
  }
  code_[i] = static_cast<std::int16_t>(code);
  gray_[i] = static_cast<std::uint16_t>(decode::binary_to_gray(static_cast<std::uint32_t>(code)));
  gain_dn_[i] = kFullScaleDn * albedo * irradiance;
}

void Renderer::shade(int bit_index, bool positive, std::uint64_t noise_key, MonoImage& out) const {
  out.width = camera_view_.width;
  out.height = camera_view_.height;
  out.pixels.resize(base_dn_.size());
  const int shift = config_.geometry.layout.bit_count - 1 - bit_index;  // Eq. 1, k = 0 is the MSB
  const std::uint16_t flip = positive ? 0 : 1;
  const float* base = base_dn_.data();
  const float* gain = gain_dn_.data();
  const std::uint16_t* gray = gray_.data();
  quantise_with_noise(
      base_dn_.size(), static_cast<float>(config_.noise_sigma_dn),
      splitmix64(config_.noise_seed ^ noise_key),
      [&](std::size_t i) {
        const int bit = ((gray[i] >> shift) & 1) ^ flip;
        return base[i] + gain[i] * static_cast<float>(bit);
      },
      out.pixels.data());
}

void Renderer::accumulate(int bit_index, bool positive, float weight,
                          std::vector<float>& sum) const {
  sum.resize(base_dn_.size(), 0.0f);
  const int shift = config_.geometry.layout.bit_count - 1 - bit_index;
  const std::uint16_t flip = positive ? 0 : 1;
  for (std::size_t i = 0; i < sum.size(); ++i) {
    const int bit = ((gray_[i] >> shift) & 1) ^ flip;
    sum[i] += weight * (base_dn_[i] + gain_dn_[i] * static_cast<float>(bit));
  }
}

void Renderer::finish(const std::vector<float>& sum, std::uint64_t noise_key,
                      MonoImage& out) const {
  out.width = camera_view_.width;
  out.height = camera_view_.height;
  out.pixels.resize(sum.size());
  quantise_with_noise(
      sum.size(), static_cast<float>(config_.noise_sigma_dn),
      splitmix64(config_.noise_seed ^ noise_key), [&](std::size_t i) { return sum[i]; },
      out.pixels.data());
}

}  // namespace avs::sim
