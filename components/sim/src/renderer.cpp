// Renderer: geometry pass (set_view) and per-frame shading (shade); see renderer.hpp.
#include "avs/sim/renderer.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>

#include "avs/decode/gray_code.hpp"

namespace avs::sim {
namespace {

constexpr float kFullScaleDn = 255.0f;
constexpr std::size_t kNoiseBankSize = std::size_t{1} << 20;
constexpr float kNoiseBankScale = 32.0f;  ///< bank entries are N(0, 1) x 32, in int8

std::uint64_t splitmix64(std::uint64_t x) {
  x += 0x9E3779B97F4A7C15ull;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}

/// Box-Muller over splitmix64: the same seed gives the same bank on every platform.
std::vector<std::int8_t> make_noise_bank(std::uint64_t seed) {
  std::vector<std::int8_t> bank(kNoiseBankSize);
  std::uint64_t state = splitmix64(seed);
  auto uniform = [&state] {  // (0, 1]
    state = splitmix64(state);
    return (static_cast<double>(state >> 11) + 1.0) / 9007199254740992.0;
  };
  for (std::size_t i = 0; i < bank.size(); i += 2) {
    const double r = std::sqrt(-2 * std::log(uniform())), phi = 2 * std::numbers::pi * uniform();
    const double pair[2] = {r * std::cos(phi), r * std::sin(phi)};
    for (int k = 0; k < 2; ++k) {
      bank[i + k] =
          static_cast<std::int8_t>(std::clamp(std::lround(pair[k] * kNoiseBankScale), -127L, 127L));
    }
  }
  return bank;
}

PinholeView make_view(const decode::LensModel& lens, double scale, double near_m) {
  // Scaling keeps pixel centres at integers: u' = (u + 0.5) s - 0.5.
  PinholeView view;
  view.width = static_cast<int>(std::ceil(lens.width * scale));
  view.height = static_cast<int>(std::ceil(lens.height * scale));
  view.fx_px = static_cast<float>(lens.fx_px * scale);
  view.fy_px = static_cast<float>(lens.fy_px * scale);
  view.cx_px = static_cast<float>((lens.cx_px + 0.5) * scale - 0.5);
  view.cy_px = static_cast<float>((lens.cy_px + 0.5) * scale - 0.5);
  view.near_m = static_cast<float>(near_m);
  return view;
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
  if (!(config_.shadow_map_scale > 0 && config_.shadow_map_scale <= 1)) {
    throw std::invalid_argument("sim::Renderer: shadow_map_scale must be in (0, 1], got " +
                                std::to_string(config_.shadow_map_scale));
  }
  camera_view_ = make_view(g.camera, 1.0, config_.near_clip_m);
  projector_ = g.projector;
  shadow_view_ = make_view(g.projector, config_.shadow_map_scale, config_.near_clip_m);
  // Only the coded rows (plus a cell of margin) matter: the others are dark in both polarities.
  const double s = config_.shadow_map_scale;
  shadow_view_.first_row = std::max(0, static_cast<int>(std::floor(g.layout.first_row * s)) - 1);
  shadow_view_.last_row =
      std::min(shadow_view_.height,
               static_cast<int>(std::ceil((g.layout.first_row + g.layout.used_rows()) * s)) + 1);
  row_code_.resize(g.projector.height);
  for (int row = 0; row < g.projector.height; ++row) {
    row_code_[row] = static_cast<std::int16_t>(decode::code_of_row(g.layout, row));
  }
  noise_bank_ = make_noise_bank(config_.noise_seed);
  R_projector_camera_ = g.R_projector_camera.cast<float>();
  t_projector_camera_m_ = g.t_projector_camera_m.cast<float>();
  projector_centre_camera_m_ = g.projector_centre_camera_m().cast<float>();
  ray_x_.resize(g.camera.width);
  ray_y_.resize(g.camera.height);
  for (int x = 0; x < g.camera.width; ++x) {
    ray_x_[x] = static_cast<float>((x - g.camera.cx_px) / g.camera.fx_px);
  }
  for (int y = 0; y < g.camera.height; ++y) {
    ray_y_[y] = static_cast<float>((y - g.camera.cy_px) / g.camera.fy_px);
  }
  const std::size_t pixels = static_cast<std::size_t>(g.camera.width) * g.camera.height;
  if (pixels > kNoiseBankSize / 2) {
    throw std::invalid_argument("sim::Renderer: camera larger than 2^19 pixels not supported");
  }
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
  // 1. Both depth buffers and the per-triangle data.
  prepare_triangles(objects);
  // 2. Per camera pixel: surface point, shadow test, shading, code.
  for (int y = 0; y < camera_view_.height; ++y) compute_row(y);
}

void Renderer::prepare_triangles(const std::vector<RenderObject>& objects) {
  camera_buffer_.reset(camera_view_.width, camera_view_.height);
  projector_buffer_.reset(shadow_view_.width, shadow_view_.height);
  normal_camera_.clear();
  triangle_object_.clear();
  triangle_albedo_dn_.clear();
  for (std::size_t o = 0; o < objects.size(); ++o) {
    if (objects[o].mesh == nullptr)
      throw std::invalid_argument("sim::Renderer: object without mesh");
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
      triangle_albedo_dn_.push_back(kFullScaleDn * static_cast<float>(objects[o].albedo));
    }
    rasterize(camera_view_, scratch_camera_, mesh.triangles, id_offset, config_.cull_back_faces,
              camera_buffer_);
    rasterize(shadow_view_, scratch_projector_, mesh.triangles, id_offset, config_.cull_back_faces,
              projector_buffer_);
  }
}

void Renderer::compute_row(int y) {
  constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
  const auto ambient = static_cast<float>(config_.ambient_level);
  const auto projector_level = static_cast<float>(config_.projector_level);
  const auto falloff2 =
      static_cast<float>(config_.falloff_reference_m * config_.falloff_reference_m);
  const auto bias = static_cast<float>(config_.shadow_bias_m);
  const auto scale = static_cast<float>(config_.shadow_map_scale);
  const auto fx = static_cast<float>(projector_.fx_px), fy = static_cast<float>(projector_.fy_px);
  const auto cx = static_cast<float>(projector_.cx_px), cy = static_cast<float>(projector_.cy_px);
  const int projector_width = projector_.width, projector_height = projector_.height;
  // q = R p + t with p = z (rx, ry, 1): R p = z (R.col(0) rx + R.col(1) ry + R.col(2)).
  const Eigen::Vector3f row_term =
      R_projector_camera_.col(1) * ray_y_[y] + R_projector_camera_.col(2);
  const Eigen::Vector3f column_term = R_projector_camera_.col(0);
  const std::size_t row_start = static_cast<std::size_t>(y) * camera_view_.width;

  for (int x = 0; x < camera_view_.width; ++x) {
    const std::size_t i = row_start + x;
    const std::int32_t id = camera_buffer_.triangle[i];
    base_dn_[i] = gain_dn_[i] = 0.0f;
    gray_[i] = 0;
    projector_row_[i] = kNaN;
    code_[i] = -1;
    if (id < 0) {
      depth_m_[i] = 0.0f;
      object_index_[i] = -1;
      continue;
    }
    const float z = 1.0f / camera_buffer_.inv_depth[i];
    const Eigen::Vector3f p_camera(ray_x_[x] * z, ray_y_[y] * z, z);
    const float albedo_dn = triangle_albedo_dn_[id];
    depth_m_[i] = z;
    object_index_[i] = triangle_object_[id];
    base_dn_[i] = albedo_dn * ambient;

    // Shading: cosine between the face normal and the direction to the projector.
    Eigen::Vector3f normal = normal_camera_[id];
    if (normal.dot(p_camera) > 0) normal = -normal;  // back face, drawn with culling off
    const Eigen::Vector3f to_projector = projector_centre_camera_m_ - p_camera;
    const float facing = normal.dot(to_projector);
    if (!(facing > 0)) continue;
    // Projection into the projector and the shadow test against its depth buffer.
    const Eigen::Vector3f q = z * (column_term * ray_x_[x] + row_term) + t_projector_camera_m_;
    if (q.z() < shadow_view_.near_m) continue;
    const float inv_qz = 1.0f / q.z();
    const float u = fx * q.x() * inv_qz + cx, v = fy * q.y() * inv_qz + cy;
    if (!(u > -0.5f && u < projector_width - 0.5f && v > -0.5f && v < projector_height - 0.5f))
      continue;
    const int row = static_cast<int>(v + 0.5f);
    const int code = row_code_[row];
    if (code < 0) continue;  // uncoded rows are dark
    const int cell_x = static_cast<int>((u + 0.5f) * scale),
              cell_y = static_cast<int>((v + 0.5f) * scale);
    const std::size_t j = static_cast<std::size_t>(cell_y) * shadow_view_.width + cell_x;
    const float w_seen = projector_buffer_.inv_depth[j];
    if (projector_buffer_.triangle[j] != id && w_seen > 0 &&
        q.z() * w_seen > 1.0f + bias * w_seen) {
      continue;  // something nearer to the projector covers this point: projector shadow
    }
    const float distance2 = to_projector.squaredNorm();
    float irradiance = projector_level * facing / std::sqrt(distance2);
    if (falloff2 > 0) irradiance *= falloff2 / distance2;
    projector_row_[i] = v;
    code_[i] = static_cast<std::int16_t>(code);
    gray_[i] = static_cast<std::uint16_t>(decode::binary_to_gray(static_cast<std::uint32_t>(code)));
    gain_dn_[i] = albedo_dn * irradiance;
  }
}

template <typename ValueFn>
void Renderer::quantise(std::uint64_t noise_key, ValueFn value, MonoImage& out) const {
  out.width = camera_view_.width;
  out.height = camera_view_.height;
  const std::size_t n = base_dn_.size();
  out.pixels.resize(n);
  const std::size_t offset =
      splitmix64(config_.noise_seed ^ noise_key) % (noise_bank_.size() - n + 1);
  const std::int8_t* noise = noise_bank_.data() + offset;
  const float sigma = static_cast<float>(config_.noise_sigma_dn) / kNoiseBankScale;
  std::uint8_t* pixels = out.pixels.data();
  for (std::size_t i = 0; i < n; ++i) {
    const float v = value(i) + sigma * static_cast<float>(noise[i]) + 0.5f;
    pixels[i] = static_cast<std::uint8_t>(std::min(std::max(v, 0.0f), kFullScaleDn));
  }
}

void Renderer::shade(int bit_index, bool positive, std::uint64_t noise_key, MonoImage& out) const {
  const int shift = config_.geometry.layout.bit_count - 1 - bit_index;  // Eq. 1: k = 0 is the MSB
  const unsigned flip = positive ? 0u : 1u;
  const float* base = base_dn_.data();
  const float* gain = gain_dn_.data();
  const std::uint16_t* gray = gray_.data();
  quantise(
      noise_key,
      [&](std::size_t i) {
        const unsigned bit = ((static_cast<unsigned>(gray[i]) >> shift) & 1u) ^ flip;
        return base[i] + gain[i] * static_cast<float>(bit);
      },
      out);
}

void Renderer::accumulate(int bit_index, bool positive, float weight,
                          std::vector<float>& sum) const {
  sum.resize(base_dn_.size(), 0.0f);
  const int shift = config_.geometry.layout.bit_count - 1 - bit_index;
  const unsigned flip = positive ? 0u : 1u;
  for (std::size_t i = 0; i < sum.size(); ++i) {
    const unsigned bit = ((static_cast<unsigned>(gray_[i]) >> shift) & 1u) ^ flip;
    sum[i] += weight * (base_dn_[i] + gain_dn_[i] * static_cast<float>(bit));
  }
}

void Renderer::finish(const std::vector<float>& sum, std::uint64_t noise_key,
                      MonoImage& out) const {
  if (sum.size() != base_dn_.size())
    throw std::invalid_argument("sim::Renderer::finish: wrong size");
  quantise(
      noise_key, [&](std::size_t i) { return sum[i]; }, out);
}

}  // namespace avs::sim
