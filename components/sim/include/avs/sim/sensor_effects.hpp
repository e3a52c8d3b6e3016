// What a real rig's optics and sensor do to the image and the ideal renderer does not (issue 19
// item 1): projector defocus and black level, camera shot, read and fixed-pattern noise and its
// response curve, glossy and textured surfaces, flickering room light. Every field defaults to
// "off", so a default RendererConfig renders exactly what it did before (the `ideal` profile);
// the `realistic` profile's values and their sources are in sensor_profile.cpp and docs/sim.md.
// Plain C++, no I/O.
#pragma once

#include <string>

namespace avs::sim {

/// The projector's lens and DMD.
struct ProjectorOptics {
  /// Light an "off" DMD mirror still sends onto the scene, as a fraction of an "on" mirror's
  /// (1 / the contrast ratio, stray light included). 0: perfectly dark stripes.
  double black_level = 0.0;
  /// Defocus by the thin-lens model: a lens of this aperture diameter focused at
  /// focus_distance_m spreads a DMD pixel over a disc of diameter
  /// aperture_m x |d - focus| / focus at projector depth d. 0: perfectly sharp at any depth.
  double aperture_m = 0.0;
  double focus_distance_m = 1.0;
  /// Blur of the in-focus image (lens resolution, DMD fill factor): Gaussian sigma in DMD
  /// pixels, added in quadrature to the defocus.
  double focused_blur_px = 0.0;

  bool blurs() const { return aperture_m > 0 || focused_blur_px > 0; }
  /// Gaussian sigma, in DMD pixels, of the pattern's edges on a surface at projector-frame
  /// depth `depth_m`, for a projector of focal length `focal_px` (a disc of diameter c has a
  /// 1-D spread of sigma = c / 4).
  double blur_sigma_px(double depth_m, double focal_px) const;
};

/// The camera's conversion of light to digital numbers (EMVA 1288's linear model, plus a
/// response curve). The light the renderer computes, in DN, is the mean signal.
struct CameraResponse {
  /// Electrons that give full scale (255 DN); > 0 adds photon shot noise (Poisson, drawn as a
  /// Gaussian of variance = signal in electrons). 0: no shot noise.
  double full_well_e = 0.0;
  /// Read (temporal dark) noise, electrons rms; needs full_well_e > 0 to convert to DN.
  double read_noise_e = 0.0;
  /// Photo-response non-uniformity: each pixel's gain is 1 + this x N(0, 1), fixed for the
  /// sensor (drawn once from the noise seed).
  double prnu_fraction = 0.0;
  /// Dark-signal non-uniformity: each pixel's offset, this x N(0, 1) DN, fixed.
  double dsnu_dn = 0.0;
  /// Output = 255 (signal / 255)^(1 / gamma); 1 = linear (machine-vision cameras' default).
  double gamma = 1.0;

  bool is_ideal() const {
    return full_well_e == 0 && read_noise_e == 0 && prnu_fraction == 0 && dsnu_dn == 0 &&
           gamma == 1.0;
  }
};

/// The camera lens's defocus (thin lens): the image of a point at depth d is a disc of diameter
/// (f / N) f |d - focus| / (d (focus - f)) on the sensor.
struct CameraOptics {
  double f_number = 0.0;  ///< N; 0: a pinhole (everything sharp)
  double focus_distance_m = 1.0;
  double focal_length_m = 0.006;  ///< Table 2's 6 mm lens; the pixel pitch is this / fx_px

  bool blurs() const { return f_number > 0; }
  /// Gaussian sigma in camera pixels at depth `depth_m` (0 or less: infinitely far) for a camera
  /// of focal length `focal_px` (sigma = disc / 4).
  double blur_sigma_px(double depth_m, double focal_px) const;
};

/// Room light on mains power flickers at twice the mains frequency.
struct AmbientFlicker {
  /// Ambient light = ambient_level x (1 + modulation x sin(2 pi frequency_hz t)); 0: steady.
  double modulation = 0.0;
  double frequency_hz = 100.0;
  /// The ambient light's mean gain over an exposure of `exposure_s` centred on `time_s`
  /// (the sine integrated over the exposure).
  double mean_gain(double time_s, double exposure_s) const;
};

/// Surfaces that are not uniform matte paint.
struct SurfaceEffects {
  /// Blinn-Phong specular lobe: reflected projector light ks x (n . h)^shininess x cos(theta),
  /// as a fraction of the projector level, white (not scaled by the albedo). 0: matte.
  double specular_fraction = 0.0;
  double shininess = 40.0;
  /// Albedo texture: albedo x (1 + contrast x (2 noise - 1)), clipped to 0..1, where noise is
  /// smooth value noise in the object's frame with features of texture_scale_m (dark and bright
  /// patches: where |I_pos - I_neg| falls below the decoder's threshold). 0: uniform albedo.
  double texture_contrast = 0.0;
  double texture_scale_m = 0.02;

  /// Texture factor at a point in the object's frame, in metres (1 without texture).
  float texture_gain(float x_m, float y_m, float z_m) const;
};

struct SensorEffects {
  ProjectorOptics projector;
  CameraOptics lens;
  CameraResponse camera;
  AmbientFlicker ambient;
  SurfaceEffects surface;

  /// Effects the geometry pass or the pattern lookup must render (not only the camera's
  /// conversion and the ambient gain).
  bool changes_pattern_light() const {
    return projector.black_level > 0 || projector.blurs() || surface.specular_fraction > 0 ||
           surface.texture_contrast > 0;
  }
  /// Empty when valid, else what is wrong (a negative aperture, a gamma of 0, ...).
  std::string problem() const;
};

}  // namespace avs::sim
