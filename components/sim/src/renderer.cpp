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
/// Flag in gray_ / column_gray_: a coded row (column) lights the pixel (codes have <= 15 bits).
constexpr std::uint16_t kCoded = 0x8000;

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

PinholeView make_view(const geometry::CameraModel& lens, double scale, double near_m) {
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

/// Per pixel of a camera row: z from 1/z, the projector coordinates (u, v) and depth qz of
/// the point and 1 / its distance to the projector centre, with q = z (column_term rx + row_term) +
/// t. Pixels with nothing (w = 0) get z = 0; points not in front of the projector get u = v = -1.
/// No control flow, so the compiler vectorises it (a free function: inside the member it did not).
void project_row(int width, const float* __restrict inv_depth, const float* __restrict ray_x,
                 const Eigen::Vector3f& column_term, const Eigen::Vector3f& row_term,
                 const Eigen::Vector3f& t, float near, float fx, float fy, float cx, float cy,
                 float ray_y, const Eigen::Vector3f& projector_centre, float* __restrict z_out,
                 float* __restrict qz_out, float* __restrict u_out, float* __restrict v_out,
                 float* __restrict inv_distance_out) {
  const float c_x = projector_centre.x(), c_y = projector_centre.y(), c_z = projector_centre.z();
  const float ax = column_term.x(), ay = column_term.y(), az = column_term.z();
  const float bx = row_term.x(), by = row_term.y(), bz = row_term.z();
  const float tx = t.x(), ty = t.y(), tz = t.z();
  for (int x = 0; x < width; ++x) {
    const float w = inv_depth[x];
    const float seen = static_cast<float>(w > 0.0f);
    const float z = seen / (w + (1.0f - seen));
    const float qx = z * (ax * ray_x[x] + bx) + tx;
    const float qy = z * (ay * ray_x[x] + by) + ty;
    const float qz = z * (az * ray_x[x] + bz) + tz;
    const float front = static_cast<float>(qz > near);
    const float inv_qz = front / (qz + (1.0f - front));
    z_out[x] = z;
    qz_out[x] = qz;
    u_out[x] = front * (fx * qx * inv_qz + cx + 1.0f) - 1.0f;
    v_out[x] = front * (fy * qy * inv_qz + cy + 1.0f) - 1.0f;
    const float dx = c_x - ray_x[x] * z, dy = c_y - ray_y * z, dz = c_z - z;
    inv_distance_out[x] = 1.0f / std::sqrt(dx * dx + dy * dy + dz * dz + 1e-12f);
  }
}

}  // namespace

std::uint64_t frame_noise_key(std::uint64_t frame_index) {
  return splitmix64(frame_index);
}

Renderer::Renderer(RendererConfig config) : config_(std::move(config)) {
  const decode::SensorGeometry& g = config_.geometry;
  if (const std::string problem = g.camera.problem(); !problem.empty()) {
    throw std::invalid_argument("sim::Renderer: camera: " + problem);
  }
  if (const std::string problem = g.projector.problem(); !problem.empty()) {
    throw std::invalid_argument("sim::Renderer: projector: " + problem);
  }
  if (config_.column_layout) {
    const decode::CodeLayout& c = *config_.column_layout;
    if (c.bit_count < 1 || c.bit_count > 15 || c.code_count < 1 ||
        c.code_count > (1 << c.bit_count) || c.rows_per_code < 1) {
      throw std::invalid_argument(
          "sim::Renderer: column_layout needs 1..15 bits, 1..2^bits codes, rows_per_code >= 1");
    }
  }
  if (g.layout.bit_count > 15) {
    throw std::invalid_argument("sim::Renderer: the row code has more than 15 bits");
  }
  if (g.camera.width <= 0 || g.camera.height <= 0 || g.projector.width <= 0 ||
      g.projector.height <= 0) {
    throw std::invalid_argument("sim::Renderer: camera and projector sizes must be positive");
  }
  if (!(config_.shadow_map_scale > 0 && config_.shadow_map_scale <= 1)) {
    throw std::invalid_argument("sim::Renderer: shadow_map_scale must be in (0, 1], got " +
                                std::to_string(config_.shadow_map_scale));
  }
  // The scene is rasterised into the ideal pinhole of the camera (rasterisation needs straight
  // lines); with lens distortion, a margin wide enough for what the distorted image sees and
  // a remap table to the camera's pixels (see remap_).
  const geometry::CameraModel pinhole = make_pinhole_and_remap(g.camera);
  camera_view_ = make_view(pinhole, 1.0, config_.near_clip_m);
  projector_ = g.projector;
  calibration_patterns_ = config_.column_layout.has_value();
  // The shadow map is rasterised in the projector's ideal pinhole (widened when it has
  // distortion, see make_projector_pinhole).
  shadow_view_ =
      make_view(make_projector_pinhole(g.projector), config_.shadow_map_scale, config_.near_clip_m);
  if (!calibration_patterns_ && !g.projector.has_distortion()) {
    // Only the coded rows (plus a cell of margin) matter: the others are dark in both
    // polarities.
    const double s = config_.shadow_map_scale;
    shadow_view_.first_row = std::max(0, static_cast<int>(std::floor(g.layout.first_row * s)) - 1);
    shadow_view_.last_row =
        std::min(shadow_view_.height,
                 static_cast<int>(std::ceil((g.layout.first_row + g.layout.used_rows()) * s)) + 1);
  }
  row_code_.resize(g.projector.height);
  for (int row = 0; row < g.projector.height; ++row) {
    row_code_[row] = static_cast<std::int16_t>(decode::code_of_row(g.layout, row));
  }
  if (calibration_patterns_) {
    column_code_.resize(g.projector.width);
    for (int column = 0; column < g.projector.width; ++column) {
      column_code_[column] =
          static_cast<std::int16_t>(decode::code_of_row(*config_.column_layout, column));
    }
  }
  noise_bank_ = make_noise_bank(config_.noise_seed);
  set_up_effects(pinhole);
  R_projector_camera_ = g.R_projector_camera.cast<float>();
  t_projector_camera_m_ = g.t_projector_camera_m.cast<float>();
  projector_centre_camera_m_ = g.projector_centre_camera_m().cast<float>();
  ray_x_.resize(pinhole.width);
  ray_y_.resize(pinhole.height);
  for (int x = 0; x < pinhole.width; ++x) {
    ray_x_[x] = static_cast<float>((x - pinhole.cx_px) / pinhole.fx_px);
  }
  for (int y = 0; y < pinhole.height; ++y) {
    ray_y_[y] = static_cast<float>((y - pinhole.cy_px) / pinhole.fy_px);
  }
  if (static_cast<std::size_t>(g.camera.width) * g.camera.height > kNoiseBankSize / 2) {
    throw std::invalid_argument("sim::Renderer: camera larger than 2^19 pixels not supported");
  }
  const std::size_t pixels = static_cast<std::size_t>(pinhole.width) * pinhole.height;
  row_z_.resize(pinhole.width);
  row_u_.resize(pinhole.width);
  row_v_.resize(pinhole.width);
  row_qz_.resize(pinhole.width);
  row_inv_distance_.resize(pinhole.width);
  base_dn_.assign(pixels, 0.0f);
  gain_dn_.assign(pixels, 0.0f);
  gray_.assign(pixels, 0);
  if (calibration_patterns_) {
    column_gray_.assign(pixels, 0);
    sub_samples_.resize(pixels);
    is_sub_sampled_.assign(pixels, 0);
  }
  truth_.depth_m.assign(pixels, 0.0f);
  truth_.projector_row.assign(pixels, std::numeric_limits<float>::quiet_NaN());
  truth_.projector_column.assign(pixels, std::numeric_limits<float>::quiet_NaN());
  truth_.object_index.assign(pixels, -1);
  truth_.code.assign(pixels, -1);
  shadow_cell_u_.assign(pixels, -1);
  shadow_cell_v_.assign(pixels, -1);
  truth_.valid = true;  // nothing in view yet
}

void Renderer::set_up_effects(const geometry::CameraModel& pinhole) {
  const SensorEffects& e = config_.effects;
  if (const std::string problem = e.problem(); !problem.empty()) {
    throw std::invalid_argument("sim::Renderer: sensor effects: " + problem);
  }
  pattern_effects_ = e.changes_pattern_light();
  if (pattern_effects_ && calibration_patterns_) {
    throw std::invalid_argument(
        "sim::Renderer: projector defocus, black level, specular and texture effects are "
        "rendered for the row codes only, not with calibration patterns (column_layout)");
  }
  const std::size_t pixels = static_cast<std::size_t>(pinhole.width) * pinhole.height;
  if (e.projector.blurs()) {
    code_position_.assign(pixels, 0.0f);
    inv_blur_codes_.assign(pixels, 0.0f);
    phi_table_.resize(512);
    for (std::size_t k = 0; k < phi_table_.size(); ++k) {
      const double z = (static_cast<double>(k) + 0.5) / 128.0;
      phi_table_[k] = static_cast<float>(0.5 * std::erfc(-z / std::numbers::sqrt2));
    }
  }
  if (e.lens.blurs()) {
    // Gaussian weights per sigma level (level / kBlurLevelsPerPixel px), normalised over the
    // kernel; level 0 is the identity.
    const std::size_t camera_pixels =
        static_cast<std::size_t>(config_.geometry.camera.width) * config_.geometry.camera.height;
    blur_level_.assign(camera_pixels, 0);
    constexpr int kTaps = 2 * kBlurRadius + 1;
    blur_weights_.assign(static_cast<std::size_t>(kBlurLevels) * kTaps, 0.0f);
    for (int level = 0; level < kBlurLevels; ++level) {
      float* k = blur_weights_.data() + static_cast<std::size_t>(level) * kTaps;
      const double sigma = static_cast<double>(level) / kBlurLevelsPerPixel;
      if (level == 0) {
        k[kBlurRadius] = 1.0f;
        continue;
      }
      double sum = 0;
      for (int t = -kBlurRadius; t <= kBlurRadius; ++t)
        sum += std::exp(-0.5 * t * t / (sigma * sigma));
      for (int t = -kBlurRadius; t <= kBlurRadius; ++t) {
        k[t + kBlurRadius] = static_cast<float>(std::exp(-0.5 * t * t / (sigma * sigma)) / sum);
      }
    }
  }
  camera_response_ = !e.camera.is_ideal();
  if (!camera_response_) return;
  const CameraResponse& c = e.camera;
  const std::size_t camera_pixels =
      static_cast<std::size_t>(config_.geometry.camera.width) * config_.geometry.camera.height;
  // The fixed pattern: drawn once from the noise seed (another stream than the frames' noise).
  const std::vector<std::int8_t> fixed = make_noise_bank(config_.noise_seed ^ 0xF1C5D0A7ull);
  prnu_gain_.resize(camera_pixels);
  dsnu_dn_.resize(camera_pixels);
  for (std::size_t i = 0; i < camera_pixels; ++i) {
    prnu_gain_[i] = 1.0f + static_cast<float>(c.prnu_fraction) * fixed[2 * i] / kNoiseBankScale;
    dsnu_dn_[i] = static_cast<float>(c.dsnu_dn) * fixed[2 * i + 1] / kNoiseBankScale;
  }
  dn_per_electron_ = c.full_well_e > 0 ? kFullScaleDn / static_cast<float>(c.full_well_e) : 0.0f;
  const float read_dn = static_cast<float>(c.read_noise_e) * dn_per_electron_;
  read_variance_dn2_ = read_dn * read_dn;
  if (c.gamma != 1.0) {
    gamma_table_.resize(1025);
    for (std::size_t k = 0; k < gamma_table_.size(); ++k) {
      const double signal = std::min(static_cast<double>(k) / 4.0, 255.0) / 255.0;
      gamma_table_[k] = static_cast<float>(255.0 * std::pow(signal, 1.0 / c.gamma));
    }
  }
}

/// Light of one row bit at a pinhole pixel as a fraction of the projector's (see
/// Renderer::row_bit_light). Defocus blurs each stripe edge by a Gaussian: the nearest edge of
/// the bit decides (the stripes of bit k are 2^(n-k) codes wide, the blur at most a few DMD
/// rows), so the light is Phi(distance / sigma) on the pixel's own side of it.
struct Renderer::RowBitLight {
  const std::uint16_t* gray;
  unsigned shift, flip;
  float black, swing;          ///< light = black + swing x bit
  const float* code_position;  ///< null: sharp stripes
  const float* inv_blur;
  const float* phi;
  float period, first_edge;  ///< of this bit's edges, in codes: first_edge + m period

  float operator()(std::size_t i) const {
    const auto g = static_cast<unsigned>(gray[i]);
    // Uncoded pixels (no kCoded flag) are dark in both polarities.
    const unsigned bit = (((g >> shift) & 1u) ^ flip) & (g >> 15);
    if (code_position == nullptr || (g >> 15) == 0) return black + swing * static_cast<float>(bit);
    float t = code_position[i] - first_edge;
    t -= period * std::floor(t / period);
    const float distance = std::min(t, period - t) * inv_blur[i];  // in sigmas
    const int k = static_cast<int>(distance * 128.0f);
    const float same_side = k < 512 ? phi[k] : 1.0f;
    return black + swing * (bit ? same_side : 1.0f - same_side);
  }
};

Renderer::RowBitLight Renderer::row_bit_light(int bit_index, bool positive) const {
  const int bit_count = config_.geometry.layout.bit_count;
  const auto shift = static_cast<unsigned>(bit_count - 1 - bit_index);  // Eq. 1: k = 0 is the MSB
  const auto black = static_cast<float>(config_.effects.projector.black_level);
  RowBitLight light{
      gray_.data(), shift, positive ? 0u : 1u, black, 1.0f - black, nullptr, nullptr, nullptr,
      0.0f,         0.0f};
  if (!code_position_.empty()) {
    // Gray bit s of code c is binary bit s XOR bit s+1: it flips at odd multiples of 2^s.
    light.code_position = code_position_.data();
    light.inv_blur = inv_blur_codes_.data();
    light.phi = phi_table_.data();
    light.period = static_cast<float>(2u << shift);
    light.first_edge = static_cast<float>(1u << shift);
  }
  return light;
}

geometry::CameraModel Renderer::make_pinhole_and_remap(const geometry::CameraModel& camera) {
  geometry::CameraModel pinhole = camera;
  pinhole.set_distortion_coefficients({});
  remap_.clear();
  if (!camera.has_distortion()) return pinhole;
  // Where the camera's pixels look in the ideal pinhole of the same K: their bounding box
  // gives the margin (the border suffices for the radial and tangential terms of real lenses).
  std::vector<Eigen::Vector2d> ideal(static_cast<std::size_t>(camera.width) * camera.height);
  double overshoot = 0.0;
  for (int v = 0; v < camera.height; ++v) {
    for (int u = 0; u < camera.width; ++u) {
      const Eigen::Vector2d p = camera.undistort_pixel(Eigen::Vector2d(u, v));
      if (!p.allFinite()) {
        throw std::invalid_argument(
            "sim::Renderer: the camera's distortion does not invert at "
            "pixel (" +
            std::to_string(u) + ", " + std::to_string(v) + ")");
      }
      ideal[static_cast<std::size_t>(v) * camera.width + u] = p;
      overshoot = std::max(
          {overshoot, -p.x(), p.x() - (camera.width - 1), -p.y(), p.y() - (camera.height - 1)});
    }
  }
  const int margin = static_cast<int>(std::ceil(overshoot)) + 2;
  if (margin > std::max(camera.width, camera.height)) {
    throw std::invalid_argument(
        "sim::Renderer: the camera's distortion sees more than twice its "
        "pinhole field of view (margin " +
        std::to_string(margin) + " px); not a lens this renderer supports");
  }
  pinhole.width += 2 * margin;
  pinhole.height += 2 * margin;
  pinhole.cx_px += margin;
  pinhole.cy_px += margin;
  // Bilinear weights of the four pinhole pixels around each camera pixel's ideal position:
  // the lens maps the pinhole's irradiance, which the sensor then samples (noise is added
  // per camera pixel, after the remap).
  remap_.resize(ideal.size());
  for (std::size_t o = 0; o < ideal.size(); ++o) {
    const double x = ideal[o].x() + margin, y = ideal[o].y() + margin;
    const int x0 = std::clamp(static_cast<int>(std::floor(x)), 0, pinhole.width - 2);
    const int y0 = std::clamp(static_cast<int>(std::floor(y)), 0, pinhole.height - 2);
    const auto ax = static_cast<float>(std::clamp(x - x0, 0.0, 1.0));
    const auto ay = static_cast<float>(std::clamp(y - y0, 0.0, 1.0));
    RemapEntry& e = remap_[o];
    e.index[0] = static_cast<std::uint32_t>(y0 * pinhole.width + x0);
    e.index[1] = e.index[0] + 1;
    e.index[2] = e.index[0] + static_cast<std::uint32_t>(pinhole.width);
    e.index[3] = e.index[2] + 1;
    e.weight[0] = (1 - ax) * (1 - ay);
    e.weight[1] = ax * (1 - ay);
    e.weight[2] = (1 - ax) * ay;
    e.weight[3] = ax * ay;
    e.nearest = e.index[(ay >= 0.5f ? 2 : 0) + (ax >= 0.5f ? 1 : 0)];
  }
  return pinhole;
}

geometry::CameraModel Renderer::make_projector_pinhole(const geometry::CameraModel& projector) {
  geometry::CameraModel pinhole = projector;
  pinhole.set_distortion_coefficients({});
  projector_margin_px_ = 0;
  if (!projector.has_distortion()) return pinhole;
  // Where the DMD's border pixels send their light in the ideal pinhole of the same K (the
  // border suffices for the radial and tangential terms of real lenses): the margin.
  double overshoot = 0.0;
  const auto add = [&](int u, int v) {
    const Eigen::Vector2d p = projector.undistort_pixel(Eigen::Vector2d(u, v));
    if (!p.allFinite() ||
        (projector.project(Eigen::Vector3d((p.x() - projector.cx_px) / projector.fx_px,
                                           (p.y() - projector.cy_px) / projector.fy_px, 1.0)) -
         Eigen::Vector2d(u, v))
                .norm() > 1e-3) {
      throw std::invalid_argument(
          "sim::Renderer: the projector's distortion does not invert at DMD pixel (" +
          std::to_string(u) + ", " + std::to_string(v) + ")");
    }
    overshoot = std::max(
        {overshoot, -p.x(), p.x() - (projector.width - 1), -p.y(), p.y() - (projector.height - 1)});
  };
  for (int u = 0; u < projector.width; ++u) {
    add(u, 0);
    add(u, projector.height - 1);
  }
  for (int v = 0; v < projector.height; ++v) {
    add(0, v);
    add(projector.width - 1, v);
  }
  const int margin = static_cast<int>(std::ceil(overshoot)) + 2;
  if (margin > std::max(projector.width, projector.height) / 2) {
    throw std::invalid_argument("sim::Renderer: the projector's distortion reaches " +
                                std::to_string(margin) +
                                " px beyond its pinhole image; not a lens this renderer supports");
  }
  projector_margin_px_ = margin;
  pinhole.width += 2 * margin;
  pinhole.height += 2 * margin;
  pinhole.cx_px += margin;
  pinhole.cy_px += margin;
  return pinhole;
}

const Renderer::Truth& Renderer::truth() const {
  if (!truth_.valid) {
    // Same computation as set_view()'s, with the ground-truth arrays written too.
    auto* self = const_cast<Renderer*>(this);
    for (int y = 0; y < camera_view_.height; ++y) self->compute_row<true>(y, &self->truth_);
    truth_.valid = true;
    if (!remap_.empty()) {
      // Per camera pixel, the pinhole pixel nearest to where it looks.
      const std::size_t n = remap_.size();
      truth_camera_.depth_m.resize(n);
      truth_camera_.projector_row.resize(n);
      truth_camera_.projector_column.resize(n);
      truth_camera_.object_index.resize(n);
      truth_camera_.code.resize(n);
      for (std::size_t o = 0; o < n; ++o) {
        const std::uint32_t j = remap_[o].nearest;
        truth_camera_.depth_m[o] = truth_.depth_m[j];
        truth_camera_.projector_row[o] = truth_.projector_row[j];
        truth_camera_.projector_column[o] = truth_.projector_column[j];
        truth_camera_.object_index[o] = truth_.object_index[j];
        truth_camera_.code[o] = truth_.code[j];
      }
    }
  }
  return remap_.empty() ? truth_ : truth_camera_;
}

namespace {

/// Pixels an object's triangles can touch in `view`: the bounding box of its projected
/// vertices with a pixel of margin (the whole view if a vertex is behind the near plane).
PixelBox screen_box(const PinholeView& view, const std::vector<Eigen::Vector3f>& vertices) {
  PixelBox whole{0, 0, view.width - 1, view.height - 1};
  float u_min = std::numeric_limits<float>::infinity(), v_min = u_min;
  float u_max = -u_min, v_max = -u_min;
  for (const Eigen::Vector3f& p : vertices) {
    if (!(p.z() >= view.near_m)) return whole;
    const float w = 1.0f / p.z();
    const float u = view.fx_px * p.x() * w + view.cx_px, v = view.fy_px * p.y() * w + view.cy_px;
    u_min = std::min(u_min, u);
    u_max = std::max(u_max, u);
    v_min = std::min(v_min, v);
    v_max = std::max(v_max, v);
  }
  if (!(u_max >= u_min) || u_max < -1.0f || v_max < -1.0f ||
      u_min > static_cast<float>(view.width) || v_min > static_cast<float>(view.height)) {
    return {};
  }
  return {std::max(0, static_cast<int>(std::floor(u_min)) - 1),
          std::max(0, static_cast<int>(std::floor(v_min)) - 1),
          std::min(view.width - 1, static_cast<int>(std::ceil(u_max)) + 1),
          std::min(view.height - 1, static_cast<int>(std::ceil(v_max)) + 1)};
}

/// `view` restricted to the pixels of `clip`.
PinholeView clipped(PinholeView view, const PixelBox& clip) {
  const int row_end = view.last_row > 0 ? view.last_row : view.height;
  view.first_row = std::max(view.first_row, clip.y0);
  view.last_row = std::max(view.first_row, std::min(row_end, clip.y1 + 1));
  view.first_col = clip.x0;
  view.last_col = clip.x1 + 1;
  return view;
}

void clear(DepthBuffer& buffer, const PixelBox& box) {
  for (int y = box.y0; y <= box.y1; ++y) {
    const std::size_t row = static_cast<std::size_t>(y) * buffer.width;
    std::fill(buffer.inv_depth.begin() + static_cast<std::ptrdiff_t>(row + box.x0),
              buffer.inv_depth.begin() + static_cast<std::ptrdiff_t>(row + box.x1 + 1), 0.0f);
    std::fill(buffer.triangle.begin() + static_cast<std::ptrdiff_t>(row + box.x0),
              buffer.triangle.begin() + static_cast<std::ptrdiff_t>(row + box.x1 + 1), -1);
  }
}

}  // namespace

void Renderer::set_view(const std::vector<RenderObject>& objects) {
  if (objects.size() > static_cast<std::size_t>(std::numeric_limits<std::int16_t>::max())) {
    throw std::invalid_argument("sim::Renderer: too many objects");
  }
  // Which objects changed since the previous view? Any change of the object list: all.
  const std::size_t n = objects.size();
  bool full = !have_last_ || n != last_mesh_.size();
  std::vector<bool> moved(n, true);
  if (!full) {
    for (std::size_t o = 0; o < n; ++o) {
      if (objects[o].mesh != last_mesh_[o] || objects[o].checkerboard != last_checkerboard_[o]) {
        full = true;
      }
      moved[o] = objects[o].albedo != last_albedo_[o] ||
                 objects[o].T_camera_object.matrix() != last_pose_[o];
    }
  }
  if (!full && std::none_of(moved.begin(), moved.end(), [](bool m) { return m; })) return;
  // 1. Vertices in both views, per-triangle data, screen boxes.
  prepare_triangles(objects);
  // 2. Regions to redo: where changed objects were or are now, in either view.
  Box camera_dirty, shadow_dirty;
  if (!full) {
    for (std::size_t o = 0; o < n; ++o) {
      if (!moved[o]) continue;
      camera_dirty.add(camera_box_[o]);
      camera_dirty.add(new_camera_box_[o]);
      shadow_dirty.add(shadow_box_[o]);
      shadow_dirty.add(new_shadow_box_[o]);
    }
    // Past about half the image the plain full pass is cheaper.
    full = 2 * camera_dirty.area() > static_cast<long>(camera_view_.width) * camera_view_.height;
  }
  if (full) {
    camera_buffer_.reset(camera_view_.width, camera_view_.height);
    projector_buffer_.reset(shadow_view_.width, shadow_view_.height);
    rasterize_all(objects, Box{0, 0, camera_view_.width - 1, camera_view_.height - 1},
                  Box{0, 0, shadow_view_.width - 1, shadow_view_.height - 1});
    // 3. Per camera pixel: surface point, shadow test, shading, code.
    for (int y = 0; y < camera_view_.height; ++y) compute_row<false>(y, nullptr);
  } else {
    clear(camera_buffer_, camera_dirty);
    clear(projector_buffer_, shadow_dirty);
    rasterize_all(objects, camera_dirty, shadow_dirty);
    // 3. Rows that see a changed region, or whose shadow test read a changed cell. Elsewhere
    // the camera buffer, the triangles seen and the cells read are all as before.
    for (int y = 0; y < camera_view_.height; ++y) {
      const bool seen = !camera_dirty.empty() && y >= camera_dirty.y0 && y <= camera_dirty.y1;
      if (seen || row_reads_shadow_cells(y, shadow_dirty)) compute_row<false>(y, nullptr);
    }
  }
  truth_.valid = false;
  have_last_ = true;
  last_mesh_.resize(n);
  last_pose_.resize(n);
  last_albedo_.resize(n);
  last_checkerboard_.resize(n);
  for (std::size_t o = 0; o < n; ++o) {
    last_mesh_[o] = objects[o].mesh;
    last_checkerboard_[o] = objects[o].checkerboard;
    last_pose_[o] = objects[o].T_camera_object.matrix();
    last_albedo_[o] = objects[o].albedo;
  }
  camera_box_ = new_camera_box_;
  shadow_box_ = new_shadow_box_;
  if (!blur_level_.empty()) update_blur_levels();
}

void Renderer::update_blur_levels() {
  // Each camera pixel's defocus from the depth it sees (its nearest pinhole pixel with lens
  // distortion); nothing seen: a point at infinity.
  const CameraOptics& lens = config_.effects.lens;
  const double fx = config_.geometry.camera.fx_px;
  const float* inv_depth = camera_buffer_.inv_depth.data();
  for (std::size_t i = 0; i < blur_level_.size(); ++i) {
    const std::size_t p = remap_.empty() ? i : remap_[i].nearest;
    const double z = inv_depth[p] > 0 ? 1.0 / inv_depth[p] : 0.0;
    const double level = std::round(lens.blur_sigma_px(z, fx) * kBlurLevelsPerPixel);
    blur_level_[i] = static_cast<std::uint8_t>(std::min(level, double{kBlurLevels - 1}));
  }
}

bool Renderer::row_reads_shadow_cells(int y, const Box& cells) const {
  if (cells.empty()) return false;
  const std::size_t row = static_cast<std::size_t>(y) * camera_view_.width;
  const std::int16_t* u = shadow_cell_u_.data() + row;
  const std::int16_t* v = shadow_cell_v_.data() + row;
  int hit = 0;  // branch-free, so it vectorises
  for (int x = 0; x < camera_view_.width; ++x) {
    hit |= static_cast<int>(u[x] >= cells.x0) & static_cast<int>(u[x] <= cells.x1) &
           static_cast<int>(v[x] >= cells.y0) & static_cast<int>(v[x] <= cells.y1);
  }
  return hit != 0;
}

void Renderer::prepare_triangles(const std::vector<RenderObject>& objects) {
  normal_camera_.clear();
  triangle_object_.clear();
  triangle_albedo_dn_.clear();
  triangle_normal_dot_projector_.clear();
  triangle_plane_offset_.clear();
  object_checkerboard_.resize(objects.size());
  object_T_object_camera_.resize(objects.size());
  camera_vertices_.resize(objects.size());
  projector_vertices_.resize(objects.size());
  new_camera_box_.resize(objects.size());
  new_shadow_box_.resize(objects.size());
  for (std::size_t o = 0; o < objects.size(); ++o) {
    if (objects[o].mesh == nullptr)
      throw std::invalid_argument("sim::Renderer: object without mesh");
    const geometry::Mesh& mesh = *objects[o].mesh;
    const Eigen::Isometry3f T = objects[o].T_camera_object.cast<float>();
    object_checkerboard_[o] = objects[o].checkerboard;
    if (objects[o].checkerboard) {
      if (const std::string why = objects[o].checkerboard->problem(); !why.empty()) {
        throw std::invalid_argument("sim::Renderer: checkerboard: " + why);
      }
    }
    object_T_object_camera_[o] = objects[o].T_camera_object.inverse();
    if (config_.effects.surface.texture_contrast > 0) {
      object_T_object_camera_f_.resize(objects.size());
      object_T_object_camera_f_[o] = object_T_object_camera_[o].cast<float>();
    }
    std::vector<Eigen::Vector3f>& camera = camera_vertices_[o];
    std::vector<Eigen::Vector3f>& projector = projector_vertices_[o];
    camera.resize(mesh.vertices.size());
    projector.resize(mesh.vertices.size());
    for (std::size_t v = 0; v < mesh.vertices.size(); ++v) {
      camera[v] = T * mesh.vertices[v];
      projector[v] = R_projector_camera_ * camera[v] + t_projector_camera_m_;
    }
    for (const Eigen::Vector3i& t : mesh.triangles) {
      const Eigen::Vector3f& a = camera[t[0]];
      normal_camera_.push_back((camera[t[1]] - a).cross(camera[t[2]] - a).normalized());
      triangle_object_.push_back(static_cast<std::int16_t>(o));
      triangle_albedo_dn_.push_back(kFullScaleDn * static_cast<float>(objects[o].albedo));
      triangle_normal_dot_projector_.push_back(
          normal_camera_.back().dot(projector_centre_camera_m_));
      triangle_plane_offset_.push_back(normal_camera_.back().dot(a));
    }
    new_camera_box_[o] = screen_box(camera_view_, camera);
    new_shadow_box_[o] = screen_box(shadow_view_, projector);
  }
}

void Renderer::rasterize_all(const std::vector<RenderObject>& objects, const Box& camera_clip,
                             const Box& shadow_clip) {
  const PinholeView camera_view = clipped(camera_view_, camera_clip);
  const PinholeView shadow_view = clipped(shadow_view_, shadow_clip);
  std::int32_t id_offset = 0;
  for (std::size_t o = 0; o < objects.size(); ++o) {
    const geometry::Mesh& mesh = *objects[o].mesh;
    if (!camera_clip.empty()) {
      rasterize(camera_view, camera_vertices_[o], mesh.triangles, id_offset,
                config_.cull_back_faces, camera_buffer_);
    }
    if (!shadow_clip.empty()) {
      rasterize(shadow_view, projector_vertices_[o], mesh.triangles, id_offset,
                config_.cull_back_faces, projector_buffer_);
    }
    id_offset += static_cast<std::int32_t>(mesh.triangles.size());
  }
}

float Renderer::textured_albedo(std::int32_t triangle, int x, int y, SubSamples* sub) const {
  // The pixel's footprint on the triangle's plane: 4 x 4 rays through the pinhole pixel.
  constexpr int kSide = 4;
  static_assert(kSide * kSide == kSubSamples);
  const auto o = static_cast<std::size_t>(triangle_object_[triangle]);
  const Checkerboard& board = *object_checkerboard_[o];
  const Eigen::Isometry3d& T_object_camera = object_T_object_camera_[o];
  const Eigen::Vector3d n = normal_camera_[triangle].cast<double>();
  const double offset = triangle_plane_offset_[triangle];
  const Eigen::Matrix3d R = R_projector_camera_.cast<double>();
  const Eigen::Vector3d t = t_projector_camera_m_.cast<double>();
  double sum = 0;
  for (int j = 0; j < kSide; ++j) {
    for (int i = 0; i < kSide; ++i) {
      const double dx = (i + 0.5) / kSide - 0.5, dy = (j + 0.5) / kSide - 0.5;
      const Eigen::Vector3d ray((x + dx - camera_view_.cx_px) / camera_view_.fx_px,
                                (y + dy - camera_view_.cy_px) / camera_view_.fy_px, 1.0);
      const Eigen::Vector3d p_camera = ray * (offset / n.dot(ray));
      const Eigen::Vector3d p_object = T_object_camera * p_camera;
      const double albedo = board.albedo(p_object.x(), p_object.y());
      sum += albedo;
      if (sub == nullptr) continue;
      const int s = j * kSide + i;
      sub->albedo[s] = static_cast<std::uint8_t>(std::lround(255 * albedo));
      sub->row_gray[s] = sub->column_gray[s] = 0;
      const Eigen::Vector3d q = R * p_camera + t;
      if (!(q.z() > config_.near_clip_m)) continue;
      const Eigen::Vector2d uv = projector_.project(q);  // with the projector's distortion
      if (!projector_.contains(uv)) continue;
      const int row = row_code_[static_cast<std::size_t>(uv.y() + 0.5)];
      const int column = column_code_[static_cast<std::size_t>(uv.x() + 0.5)];
      if (row >= 0) {
        sub->row_gray[s] = static_cast<std::uint16_t>(
            kCoded | decode::binary_to_gray(static_cast<std::uint32_t>(row)));
      }
      if (column >= 0) {
        sub->column_gray[s] = static_cast<std::uint16_t>(
            kCoded | decode::binary_to_gray(static_cast<std::uint32_t>(column)));
      }
    }
  }
  return static_cast<float>(sum / kSubSamples);
}

template <bool kWithTruth>
void Renderer::compute_row(int y, Truth* truth) {
  constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
  const int width = camera_view_.width;
  const std::size_t row_start = static_cast<std::size_t>(y) * width;
  // Locals, so the compiler need not reload members after every store.
  const float* inv_depth = camera_buffer_.inv_depth.data() + row_start;
  const std::int32_t* ids = camera_buffer_.triangle.data() + row_start;
  const float* ray_x = ray_x_.data();
  const float ray_y = ray_y_[y];
  float* base_out = base_dn_.data() + row_start;
  float* gain_out = gain_dn_.data() + row_start;
  std::uint16_t* gray_out = gray_.data() + row_start;
  std::uint16_t* column_gray_out =
      calibration_patterns_ ? column_gray_.data() + row_start : nullptr;
  const std::int16_t* column_code = column_code_.data();
  const bool calibration = calibration_patterns_;
  std::int16_t* cell_u_out = shadow_cell_u_.data() + row_start;
  std::int16_t* cell_v_out = shadow_cell_v_.data() + row_start;
  const Eigen::Vector3f* normals = normal_camera_.data();
  const float* albedo_dn = triangle_albedo_dn_.data();
  const float* normal_dot_projector = triangle_normal_dot_projector_.data();
  const std::int16_t* row_code = row_code_.data();
  const float* shadow_depth = projector_buffer_.inv_depth.data();
  const std::int32_t* shadow_id = projector_buffer_.triangle.data();
  const int shadow_width = shadow_view_.width;
  const auto ambient = static_cast<float>(config_.ambient_level);
  const auto projector_level = static_cast<float>(config_.projector_level);
  const auto falloff2 =
      static_cast<float>(config_.falloff_reference_m * config_.falloff_reference_m);
  const auto bias = static_cast<float>(config_.shadow_bias_m);
  const SurfaceEffects& surface = config_.effects.surface;
  const bool texture = surface.texture_contrast > 0;
  const auto specular = static_cast<float>(surface.specular_fraction);
  const auto shininess = static_cast<float>(surface.shininess);
  const auto specular_cutoff = static_cast<float>(std::pow(1e-3, 1.0 / surface.shininess));
  const ProjectorOptics& blur = config_.effects.projector;
  const bool defocus = !code_position_.empty();
  const auto focus_m = static_cast<float>(blur.focus_distance_m);
  const auto blur_disc_px =  // x |qz - focus| / qz: the disc's sigma in DMD rows
      static_cast<float>(blur.aperture_m / blur.focus_distance_m * projector_.fy_px / 4.0);
  const auto focused_blur2 = static_cast<float>(blur.focused_blur_px * blur.focused_blur_px);
  const auto first_coded_row = static_cast<float>(config_.geometry.layout.first_row);
  const auto rows_per_code = static_cast<float>(config_.geometry.layout.rows_per_code);
  const auto scale = static_cast<float>(config_.shadow_map_scale);
  const auto near = shadow_view_.near_m;
  const auto fx = static_cast<float>(projector_.fx_px), fy = static_cast<float>(projector_.fy_px);
  const auto cx = static_cast<float>(projector_.cx_px), cy = static_cast<float>(projector_.cy_px);
  const auto u_max = static_cast<float>(projector_.width) - 0.5f;
  const auto v_max = static_cast<float>(projector_.height) - 0.5f;
  // Projector distortion: project_row gives coordinates in the ideal pinhole widened by the
  // margin (the shadow map's view), which the lens then maps to the DMD pixel that lights them.
  const bool distorted = projector_.has_distortion();
  const auto margin = static_cast<float>(projector_margin_px_);
  const float ideal_cx = cx + margin, ideal_cy = cy + margin;
  const float ideal_u_max = u_max + 2 * margin, ideal_v_max = v_max + 2 * margin;
  // q = R p + t with p = z (rx, ry, 1): R p = z (R.col(0) rx + R.col(1) ry + R.col(2)).
  const Eigen::Vector3f row_term = R_projector_camera_.col(1) * ray_y + R_projector_camera_.col(2);
  const Eigen::Vector3f column_term = R_projector_camera_.col(0);
  const Eigen::Vector3f t = t_projector_camera_m_;

  // Pass 1 (branch-free, vectorised): depth and projector coordinates of every pixel.
  project_row(width, inv_depth, ray_x, column_term, row_term, t, near, fx, fy, ideal_cx, ideal_cy,
              ray_y, projector_centre_camera_m_, row_z_.data(), row_qz_.data(), row_u_.data(),
              row_v_.data(), row_inv_distance_.data());
  const float* inv_distance = row_inv_distance_.data();
  const float* z_row = row_z_.data();
  const float* qz_row = row_qz_.data();
  const float* u_row = row_u_.data();
  const float* v_row = row_v_.data();
  // Pass 2: light, projector image bounds, coded rows and the shadow test.
  for (int x = 0; x < width; ++x) {
    const std::int32_t id = ids[x];
    gray_out[x] = 0;
    if (calibration) {
      column_gray_out[x] = 0;
      is_sub_sampled_[row_start + x] = 0;
    }
    cell_u_out[x] = cell_v_out[x] = -1;
    if constexpr (kWithTruth) {
      truth->projector_row[row_start + x] = kNaN;
      truth->projector_column[row_start + x] = kNaN;
      truth->code[row_start + x] = -1;
      truth->depth_m[row_start + x] = id < 0 ? 0.0f : z_row[x];
      truth->object_index[row_start + x] = id < 0 ? -1 : triangle_object_[id];
    }
    base_out[x] = gain_out[x] = 0.0f;
    if (id < 0) continue;
    const bool textured =
        object_checkerboard_[static_cast<std::size_t>(triangle_object_[id])] != nullptr;
    SubSamples* sub = textured && calibration ? &sub_samples_[row_start + x] : nullptr;
    if (calibration) is_sub_sampled_[row_start + x] = sub != nullptr;
    float albedo = textured ? kFullScaleDn * textured_albedo(id, x, y, sub) : albedo_dn[id];
    if (texture) {  // mottled paint, fixed to the object (value noise in its frame)
      const Eigen::Vector3f p_object =
          object_T_object_camera_f_[static_cast<std::size_t>(triangle_object_[id])] *
          Eigen::Vector3f(z_row[x] * ray_x[x], z_row[x] * ray_y, z_row[x]);
      albedo = std::min(albedo * surface.texture_gain(p_object.x(), p_object.y(), p_object.z()),
                        kFullScaleDn);
    }
    base_out[x] = albedo * ambient;
    // cos(normal, direction to the projector): n.(c - p) with p = z ray, n.c per triangle.
    const Eigen::Vector3f& n = normals[id];
    const float n_ray = n.x() * ray_x[x] + n.y() * ray_y + n.z();
    float facing = normal_dot_projector[id] - z_row[x] * n_ray;
    if (n_ray > 0) facing = -facing;                     // back face, drawn with culling off
    if (!(facing > 0)) continue;                         // turned away from the projector
    const float u_ideal = u_row[x], v_ideal = v_row[x];  // in the (widened) ideal pinhole
    float u = u_ideal, v = v_ideal;                      // on the DMD
    if (distorted) {
      if (!(qz_row[x] > near) ||
          !(u_ideal > -0.5f && u_ideal < ideal_u_max && v_ideal > -0.5f && v_ideal < ideal_v_max)) {
        continue;  // behind the projector or outside what its lens can reach
      }
      const Eigen::Vector2d xy =
          projector_.distort(Eigen::Vector2d((u_ideal - ideal_cx) / fx, (v_ideal - ideal_cy) / fy));
      u = fx * static_cast<float>(xy.x()) + cx;
      v = fy * static_cast<float>(xy.y()) + cy;
    }
    bool lit = u > -0.5f && u < u_max && v > -0.5f && v < v_max;  // also false behind it
    const int code = lit ? row_code[static_cast<int>(v + 0.5f)] : -1;
    if (lit && (code >= 0 || calibration)) {
      const auto cell_u = static_cast<std::size_t>((u_ideal + 0.5f) * scale);
      const auto cell_v = static_cast<std::size_t>((v_ideal + 0.5f) * scale);
      const std::size_t j = cell_v * shadow_width + cell_u;
      cell_u_out[x] = static_cast<std::int16_t>(cell_u);
      cell_v_out[x] = static_cast<std::int16_t>(cell_v);
      const float w_seen = shadow_depth[j];
      // Something nearer to the projector covers this point: projector shadow.
      lit = shadow_id[j] == id || !(w_seen > 0) || qz_row[x] * w_seen <= 1.0f + bias * w_seen;
    }
    // Shadowed, outside the projector, or (row codes only) an uncoded (dark) row.
    if (!lit || (code < 0 && !calibration)) continue;
    float irradiance = projector_level * facing * inv_distance[x];
    if (falloff2 > 0) irradiance *= falloff2 * inv_distance[x] * inv_distance[x];
    gain_out[x] = albedo * irradiance;
    if (sub != nullptr) gain_out[x] = kFullScaleDn * irradiance;  // albedo per sub-sample
    if (specular > 0) {
      // Blinn-Phong: half vector of the directions to the projector and to the camera.
      const Eigen::Vector3f p(z_row[x] * ray_x[x], z_row[x] * ray_y, z_row[x]);
      const Eigen::Vector3f h =
          ((projector_centre_camera_m_ - p) * inv_distance[x] - p.normalized()).normalized();
      const float n_h = n_ray > 0 ? -n.dot(h) : n.dot(h);
      // Below the cutoff the lobe is under 1e-3 of its peak: skip the pow.
      if (n_h > specular_cutoff) {
        gain_out[x] += kFullScaleDn * specular * std::pow(n_h, shininess) * irradiance;
      }
    }
    if (defocus && code >= 0) {
      const std::size_t i = row_start + x;
      code_position_[i] = (v + 0.5f - first_coded_row) / rows_per_code;
      // ProjectorOptics::blur_sigma_px, in float (the double version cost a tenth of the pass).
      const float defocus_px = blur_disc_px * std::abs(qz_row[x] - focus_m) / qz_row[x];
      const float sigma_px = std::sqrt(defocus_px * defocus_px + focused_blur2);
      inv_blur_codes_[i] = rows_per_code / std::max(sigma_px, 1e-3f);
    }
    if constexpr (kWithTruth) {
      truth->projector_column[row_start + x] = u;
      if (code >= 0) {
        truth->projector_row[row_start + x] = v;
        truth->code[row_start + x] = static_cast<std::int16_t>(code);
      }
    }
    if (code >= 0) {
      gray_out[x] = static_cast<std::uint16_t>(
          kCoded | decode::binary_to_gray(static_cast<std::uint32_t>(code)));
    }
    if (calibration) {
      const int column = column_code[static_cast<int>(u + 0.5f)];
      if (column >= 0) {
        column_gray_out[x] = static_cast<std::uint16_t>(
            kCoded | decode::binary_to_gray(static_cast<std::uint32_t>(column)));
      }
    }
  }
}

template <typename ValueFn>
void Renderer::quantise(std::uint64_t noise_key, ValueFn value, MonoImage& out) const {
  out.width = width();
  out.height = height();
  const std::size_t n = static_cast<std::size_t>(out.width) * static_cast<std::size_t>(out.height);
  out.pixels.resize(n);
  const std::size_t offset =
      splitmix64(config_.noise_seed ^ noise_key) % (noise_bank_.size() - n + 1);
  const std::int8_t* noise = noise_bank_.data() + offset;
  const float sigma = static_cast<float>(config_.noise_sigma_dn) / kNoiseBankScale;
  std::uint8_t* pixels = out.pixels.data();
  // The light reaching camera pixel i: the pinhole's, remapped with lens distortion.
  const auto light_at = [&](std::size_t i) {
    if (remap_.empty()) return value(i);
    const RemapEntry& e = remap_[i];
    return e.weight[0] * value(e.index[0]) + e.weight[1] * value(e.index[1]) +
           e.weight[2] * value(e.index[2]) + e.weight[3] * value(e.index[3]);
  };
  // Light (DN) to pixel values: the camera's response with its noise, or the plain Gaussian.
  const auto expose = [&](auto light) {
    if (!camera_response_) {
      for (std::size_t i = 0; i < n; ++i) {
        const float v = light(i) + sigma * static_cast<float>(noise[i]) + 0.5f;
        pixels[i] = static_cast<std::uint8_t>(std::min(std::max(v, 0.0f), kFullScaleDn));
      }
      return;
    }
    // EMVA 1288's linear camera: gain and offset non-uniformity, then temporal noise of
    // variance signal / (e-/DN) + read noise^2 (+ the plain Gaussian noise), then the response
    // curve. The noise bank holds N(0, 1) x 32.
    const float fixed_variance = sigma * sigma * kNoiseBankScale * kNoiseBankScale;
    const float per_electron = dn_per_electron_, read_variance = read_variance_dn2_;
    const float* prnu = prnu_gain_.data();
    const float* dsnu = dsnu_dn_.data();
    const float* gamma = gamma_table_.empty() ? nullptr : gamma_table_.data();
    for (std::size_t i = 0; i < n; ++i) {
      const float signal = light(i) * prnu[i] + dsnu[i];
      const float variance = std::max(signal, 0.0f) * per_electron + read_variance + fixed_variance;
      float v = signal + std::sqrt(variance) * static_cast<float>(noise[i]) / kNoiseBankScale;
      if (gamma != nullptr) {
        const float k = std::min(std::max(v, 0.0f), 255.0f) * 4.0f;
        const auto k0 = static_cast<std::size_t>(k);
        const std::size_t k1 = std::min<std::size_t>(k0 + 1, 1024);
        v = gamma[k0] + (gamma[k1] - gamma[k0]) * (k - static_cast<float>(k0));
      }
      pixels[i] = static_cast<std::uint8_t>(std::min(std::max(v + 0.5f, 0.0f), kFullScaleDn));
    }
  };
  if (!blur_level_.empty()) {
    // Camera defocus: the light image blurred by each pixel's own Gaussian, then exposed.
    blur_in_.resize(n);
    for (std::size_t i = 0; i < n; ++i) blur_in_[i] = light_at(i);
    defocus_camera_image();
    expose([&](std::size_t i) { return blur_in_[i]; });
    return;
  }
  if (camera_response_ || !remap_.empty()) {
    expose(light_at);
    return;
  }
  for (std::size_t i = 0; i < n; ++i) {  // the ideal camera: one vectorised loop
    const float v = value(i) + sigma * static_cast<float>(noise[i]) + 0.5f;
    pixels[i] = static_cast<std::uint8_t>(std::min(std::max(v, 0.0f), kFullScaleDn));
  }
}

void Renderer::defocus_camera_image() const {
  // Separable gather: each output pixel weighs its neighbours with the Gaussian of its own
  // depth's sigma (blur_level_: per camera pixel, kBlurLevelsPerPixel levels per pixel of
  // sigma, kernel radius kBlurRadius); borders repeat the edge pixel.
  const int w = width(), h = height();
  blur_tmp_.resize(blur_in_.size());
  const float* weights = blur_weights_.data();
  constexpr int kTaps = 2 * kBlurRadius + 1;
  const auto kernel = [&](std::size_t i) {
    return weights + static_cast<std::size_t>(blur_level_[i]) * kTaps;
  };
  for (int y = 0; y < h; ++y) {
    const std::size_t row = static_cast<std::size_t>(y) * w;
    const float* in = blur_in_.data() + row;
    float* out = blur_tmp_.data() + row;
    for (int x = 0; x < w; ++x) {
      const float* k = kernel(row + x);
      float sum = 0;
      if (x >= kBlurRadius && x + kBlurRadius < w) {
        for (int t = 0; t < kTaps; ++t) sum += k[t] * in[x - kBlurRadius + t];
      } else {
        for (int t = 0; t < kTaps; ++t) sum += k[t] * in[std::clamp(x - kBlurRadius + t, 0, w - 1)];
      }
      out[x] = sum;
    }
  }
  for (int y = 0; y < h; ++y) {
    const std::size_t row = static_cast<std::size_t>(y) * w;
    const float* rows[kTaps];
    for (int t = 0; t < kTaps; ++t) {
      rows[t] = blur_tmp_.data() +
                static_cast<std::size_t>(std::clamp(y - kBlurRadius + t, 0, h - 1)) * w;
    }
    float* out = blur_in_.data() + row;
    for (int x = 0; x < w; ++x) {
      const float* k = kernel(row + x);
      float sum = 0;
      for (int t = 0; t < kTaps; ++t) sum += k[t] * rows[t][x];
      out[x] = sum;
    }
  }
}

void Renderer::shade(int bit_index, bool positive, std::uint64_t noise_key, MonoImage& out,
                     float ambient_gain) const {
  shade(FramePattern{ProjectorFrame::kRowBit, bit_index, positive}, noise_key, out, ambient_gain);
}

void Renderer::shade(const FramePattern& pattern, std::uint64_t noise_key, MonoImage& out,
                     float ambient_gain) const {
  const float* base = base_dn_.data();
  const float* gain = gain_dn_.data();
  const float ambient = ambient_gain;  // x 1.0f is exact: the steady-light images are unchanged
  if (pattern.frame == ProjectorFrame::kBlack) {
    quantise(
        noise_key, [&](std::size_t i) { return base[i] * ambient; }, out);
    return;
  }
  if (!calibration_patterns_ && pattern.frame != ProjectorFrame::kRowBit) {
    throw std::logic_error(
        "sim::Renderer: white and column-code frames need RendererConfig::column_layout");
  }
  // Sub-sampled pixels (a printed target, calibration patterns): the pattern's light
  // integrated over the pixel, sub-sample by sub-sample with its own albedo.
  const std::uint8_t* sub_sampled = is_sub_sampled_.data();
  const SubSamples* subs = sub_samples_.data();
  constexpr float kSubScale = 1.0f / (kSubSamples * kFullScaleDn);
  if (pattern.frame == ProjectorFrame::kWhite) {
    quantise(
        noise_key,
        [&](std::size_t i) {
          if (!sub_sampled[i]) return base[i] * ambient + gain[i];
          int sum = 0;
          for (int s = 0; s < kSubSamples; ++s) {
            sum += subs[i].albedo[s] * ((subs[i].row_gray[s] | subs[i].column_gray[s]) >> 15);
          }
          return base[i] * ambient + gain[i] * kSubScale * static_cast<float>(sum);
        },
        out);
    return;
  }
  const bool columns = pattern.frame == ProjectorFrame::kColumnBit;
  const int bit_count =
      columns ? config_.column_layout->bit_count : config_.geometry.layout.bit_count;
  if (pattern.bit_index < 0 || pattern.bit_index >= bit_count) {
    throw std::invalid_argument("sim::Renderer: bit " + std::to_string(pattern.bit_index) +
                                " outside the code's " + std::to_string(bit_count) + " bits");
  }
  const int shift = bit_count - 1 - pattern.bit_index;  // Eq. 1: k = 0 is the MSB
  const unsigned flip = pattern.positive ? 0u : 1u;
  const std::uint16_t* gray = columns ? column_gray_.data() : gray_.data();
  const auto bit_of = [shift, flip](unsigned g) {
    // Uncoded pixels (no kCoded flag) are dark in both polarities.
    return (((g >> shift) & 1u) ^ flip) & (g >> 15);
  };
  if (!calibration_patterns_ && pattern_effects_) {
    const RowBitLight light = row_bit_light(pattern.bit_index, pattern.positive);
    quantise(
        noise_key, [&](std::size_t i) { return base[i] * ambient + gain[i] * light(i); }, out);
    return;
  }
  if (!calibration_patterns_) {
    quantise(
        noise_key,
        [&](std::size_t i) {
          return base[i] * ambient + gain[i] * static_cast<float>(bit_of(gray[i]));
        },
        out);
    return;
  }
  quantise(
      noise_key,
      [&](std::size_t i) {
        if (!sub_sampled[i]) {
          return base[i] * ambient + gain[i] * static_cast<float>(bit_of(gray[i]));
        }
        const std::uint16_t* sub_gray = columns ? subs[i].column_gray : subs[i].row_gray;
        int sum = 0;
        for (int s = 0; s < kSubSamples; ++s) sum += subs[i].albedo[s] * bit_of(sub_gray[s]);
        return base[i] * ambient + gain[i] * kSubScale * static_cast<float>(sum);
      },
      out);
}

void Renderer::accumulate(int bit_index, bool positive, float weight, std::vector<float>& sum,
                          float ambient_gain) const {
  if (calibration_patterns_) {
    // Sub-sampled pixels keep their albedo per sub-sample, which this sum does not read.
    throw std::logic_error("sim::Renderer: motion blur is not rendered with calibration patterns");
  }
  sum.resize(base_dn_.size(), 0.0f);
  if (pattern_effects_) {
    const RowBitLight light = row_bit_light(bit_index, positive);
    for (std::size_t i = 0; i < sum.size(); ++i) {
      sum[i] += weight * (base_dn_[i] * ambient_gain + gain_dn_[i] * light(i));
    }
    return;
  }
  const int shift = config_.geometry.layout.bit_count - 1 - bit_index;
  const unsigned flip = positive ? 0u : 1u;
  for (std::size_t i = 0; i < sum.size(); ++i) {
    const auto g = static_cast<unsigned>(gray_[i]);
    const unsigned bit = (((g >> shift) & 1u) ^ flip) & (g >> 15);
    sum[i] += weight * (base_dn_[i] * ambient_gain + gain_dn_[i] * static_cast<float>(bit));
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
