// Sensor effects: the few closed forms behind sensor_effects.hpp (the per-pixel work is in the
// renderer's passes).
#include "avs/sim/sensor_effects.hpp"

#include <cmath>
#include <cstdint>
#include <numbers>

namespace avs::sim {
namespace {

/// Hash of a lattice point to [0, 1) (a 32-bit integer mix; the same everywhere).
float lattice_value(std::int32_t x, std::int32_t y, std::int32_t z) {
  std::uint32_t h = static_cast<std::uint32_t>(x) * 0x8DA6B343u ^
                    static_cast<std::uint32_t>(y) * 0xD8163841u ^
                    static_cast<std::uint32_t>(z) * 0xCB1AB31Fu;
  h ^= h >> 16;
  h *= 0x7FEB352Du;
  h ^= h >> 15;
  h *= 0x846CA68Bu;
  h ^= h >> 16;
  return static_cast<float>(h >> 8) * (1.0f / 16777216.0f);
}

/// Smooth value noise in [0, 1]: the lattice values trilinearly blended with a smoothstep.
float value_noise(float x, float y, float z) {
  const float fx = std::floor(x), fy = std::floor(y), fz = std::floor(z);
  const auto ix = static_cast<std::int32_t>(fx), iy = static_cast<std::int32_t>(fy),
             iz = static_cast<std::int32_t>(fz);
  const auto smooth = [](float t) { return t * t * (3.0f - 2.0f * t); };
  const float tx = smooth(x - fx), ty = smooth(y - fy), tz = smooth(z - fz);
  const auto lerp = [](float a, float b, float t) { return a + (b - a) * t; };
  float face[2];
  for (int dz = 0; dz < 2; ++dz) {
    const float c0 = lerp(lattice_value(ix, iy, iz + dz), lattice_value(ix + 1, iy, iz + dz), tx);
    const float c1 =
        lerp(lattice_value(ix, iy + 1, iz + dz), lattice_value(ix + 1, iy + 1, iz + dz), tx);
    face[dz] = lerp(c0, c1, ty);
  }
  return lerp(face[0], face[1], tz);
}

}  // namespace

double ProjectorOptics::blur_sigma_px(double depth_m, double focal_px) const {
  double defocus_px = 0;
  if (aperture_m > 0 && depth_m > 0) {
    // Blur disc on the surface: aperture x |d - focus| / focus; one DMD pixel there spans
    // d / focal_px metres.
    const double disc_m = aperture_m * std::abs(depth_m - focus_distance_m) / focus_distance_m;
    defocus_px = disc_m * focal_px / depth_m / 4.0;
  }
  return std::sqrt(defocus_px * defocus_px + focused_blur_px * focused_blur_px);
}

double CameraOptics::blur_sigma_px(double depth_m, double focal_px) const {
  if (!blurs()) return 0.0;
  const double f = focal_length_m, aperture_m = f / f_number;
  // |d - focus| / d, and its limit 1 for a point at infinity.
  const double defocus = depth_m > 0 ? std::abs(depth_m - focus_distance_m) / depth_m : 1.0;
  const double disc_m = aperture_m * f * defocus / (focus_distance_m - f);
  return disc_m * focal_px / f / 4.0;  // pitch = f / focal_px
}

double AmbientFlicker::mean_gain(double time_s, double exposure_s) const {
  if (modulation == 0) return 1.0;
  const double w = 2 * std::numbers::pi * frequency_hz;
  // (1 / e) integral of sin(w t) over [t - e/2, t + e/2] = sin(w t) sinc(w e / 2).
  const double half = w * exposure_s / 2;
  const double sinc = half == 0 ? 1.0 : std::sin(half) / half;
  return 1.0 + modulation * std::sin(w * time_s) * sinc;
}

float SurfaceEffects::texture_gain(float x_m, float y_m, float z_m) const {
  if (texture_contrast == 0) return 1.0f;
  const float s = 1.0f / static_cast<float>(texture_scale_m);
  // One octave (patches of texture_scale_m): a second one doubled the realistic profile's
  // geometry-pass cost for detail finer than a pixel at 1 m.
  const float n = value_noise(x_m * s, y_m * s, z_m * s);
  return 1.0f + static_cast<float>(texture_contrast) * (2.0f * n - 1.0f);
}

std::string SensorEffects::problem() const {
  const auto bad = [](double v) { return !std::isfinite(v) || v < 0; };
  if (bad(projector.black_level) || projector.black_level >= 1)
    return "projector black_level must be in [0, 1)";
  if (bad(projector.aperture_m)) return "projector aperture_m must be >= 0";
  if (!(projector.focus_distance_m > 0) || !std::isfinite(projector.focus_distance_m))
    return "projector focus_distance_m must be > 0";
  if (bad(projector.focused_blur_px)) return "projector focused_blur_px must be >= 0";
  if (bad(lens.f_number)) return "lens f_number must be >= 0";
  if (!(lens.focal_length_m > 0) || !std::isfinite(lens.focal_length_m))
    return "lens focal_length_m must be > 0";
  if (!(lens.focus_distance_m > lens.focal_length_m) || !std::isfinite(lens.focus_distance_m))
    return "lens focus_distance_m must be beyond the focal length";
  if (bad(camera.full_well_e)) return "camera full_well_e must be >= 0";
  if (bad(camera.read_noise_e)) return "camera read_noise_e must be >= 0";
  if (camera.read_noise_e > 0 && camera.full_well_e == 0)
    return "camera read_noise_e needs full_well_e > 0 (electrons per DN)";
  if (bad(camera.prnu_fraction) || camera.prnu_fraction > 0.5)
    return "camera prnu_fraction must be in [0, 0.5]";
  if (bad(camera.dsnu_dn)) return "camera dsnu_dn must be >= 0";
  if (!(camera.gamma > 0) || !std::isfinite(camera.gamma)) return "camera gamma must be > 0";
  if (bad(ambient.modulation) || ambient.modulation > 1)
    return "ambient flicker modulation must be in [0, 1]";
  if (!(ambient.frequency_hz > 0) || !std::isfinite(ambient.frequency_hz))
    return "ambient flicker frequency_hz must be > 0";
  if (bad(surface.specular_fraction)) return "surface specular_fraction must be >= 0";
  if (!(surface.shininess >= 1) || !std::isfinite(surface.shininess))
    return "surface shininess must be >= 1";
  if (bad(surface.texture_contrast) || surface.texture_contrast > 1)
    return "surface texture_contrast must be in [0, 1]";
  if (!(surface.texture_scale_m > 0) || !std::isfinite(surface.texture_scale_m))
    return "surface texture_scale_m must be > 0";
  return {};
}

}  // namespace avs::sim
