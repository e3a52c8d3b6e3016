// The named sensor profiles. The `realistic` values are in docs/sim.md with their sources; the
// paper gives none of them, so each is a datasheet figure of the paper's parts where one
// exists, else a typical figure of the part's class, marked as our estimate there.
#include "avs/sim/sensor_profile.hpp"

#include <stdexcept>
#include <string>

namespace avs::sim {

SensorProfile parse_sensor_profile(std::string_view name) {
  if (name == "ideal") return SensorProfile::kIdeal;
  if (name == "realistic") return SensorProfile::kRealistic;
  throw std::invalid_argument("unknown sensor profile '" + std::string(name) +
                              "': expected ideal or realistic");
}

const char* to_string(SensorProfile profile) {
  return profile == SensorProfile::kIdeal ? "ideal" : "realistic";
}

void apply_sensor_profile(SensorProfile profile, SimulatorConfig& config) {
  RendererConfig& r = config.renderer;
  if (profile == SensorProfile::kIdeal) {
    const SimulatorConfig ideal;
    r.effects = ideal.renderer.effects;
    r.noise_sigma_dn = ideal.renderer.noise_sigma_dn;
    config.motion_blur_samples = ideal.motion_blur_samples;
    return;
  }
  SensorEffects& e = r.effects;
  // Projector: DLP LightCrafter 4500 (Table 1).
  e.projector.black_level = 0.002;     // 500:1 (datasheet 1000:1 full on/off; room stray light)
  e.projector.aperture_m = 0.004;      // our estimate (pico projector lens, about f/2)
  e.projector.focus_distance_m = 1.0;  // issue 19: focused at 1 m, the middle of 0.5-2 m
  e.projector.focused_blur_px = 0.5;   // our estimate (lens resolution at the DMD pitch)
  // Camera lens: Table 2's 6 mm lens at f/2 (our choice: open for light at 1 ms exposures),
  // focused at 1 m like the projector.
  e.lens.f_number = 2.0;
  e.lens.focus_distance_m = 1.0;
  e.lens.focal_length_m = 0.006;
  // Camera: Photron IDP-Express (Table 2); its sensor's EMVA 1288 figures are not published,
  // these are typical of 10 um high-speed CMOS pixels.
  e.camera.full_well_e = 12000;
  e.camera.read_noise_e = 25;
  e.camera.prnu_fraction = 0.01;
  e.camera.dsnu_dn = 0.5;
  e.camera.gamma = 1.0;  // linear, as machine-vision cameras deliver by default
  r.noise_sigma_dn = 0;  // the temporal noise is the shot and read noise above
  // Room light: fluorescent or cheap LED lighting on 50 Hz mains.
  e.ambient.modulation = 0.3;
  e.ambient.frequency_hz = 100;
  // Surfaces: a glossy, mottled plastic toy.
  e.surface.specular_fraction = 0.3;
  e.surface.shininess = 40;
  e.surface.texture_contrast = 0.4;
  e.surface.texture_scale_m = 0.02;
  // The ken moves 1 mm during a 1 ms exposure at 1 m/s: three poses over the exposure.
  config.motion_blur_samples = 3;
}

}  // namespace avs::sim
