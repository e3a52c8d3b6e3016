// Projector-camera renderer core (issue 3 item 1): what the paper's camera sees while the
// projector shows one Gray-code pattern (section 4.1, Eq. 1). Plain C++ over Eigen, no I/O.
//
// Two passes. set_view() runs once per pose: it rasterises every mesh into the camera's and
// the projector's depth buffers and stores, per camera pixel, the visible surface point, its
// shading and the Gray code of the projector row that lights it (none when the projector
// does not see the point: projector shadow). shade() runs once per frame: pattern bit
// lookup, intensity = albedo x (ambient + projector x bit x shading) + noise, clipped to
// 8 bits.
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include <Eigen/Geometry>

#include "avs/decode/sensor_geometry.hpp"
#include "avs/geometry/mesh.hpp"
#include "avs/sim/checkerboard.hpp"
#include "avs/sim/rasterizer.hpp"
#include "avs/sim/sensor_effects.hpp"

namespace avs::sim {

struct RendererConfig {
  /// Camera and projector lenses, their relative pose (any R, t) and the code layout of the
  /// row codes: the decoder's defaults (Tables 1-2, sections 4.1 and 4.3; see
  /// decode/sensor_geometry.hpp). Both lenses' distortion is rendered: the camera's as the
  /// ideal pinhole image remapped bilinearly to the camera's pixels before noise, the
  /// projector's by looking each lit point's ideal projector coordinates up in the distorted
  /// DMD image (the pattern pixel that really lights it).
  decode::SensorGeometry geometry = decode::default_sensor_geometry();
  /// Calibration patterns (issue 14): when set, the renderer also shows Gray codes over the
  /// projector's columns with this layout (its "rows" are DMD columns), all-white frames, and
  /// lights and shadow-tests every DMD row, not only the coded rows of `geometry.layout`.
  /// Unset (the 500 Hz simulator): row codes only; white and column frames throw.
  std::optional<decode::CodeLayout> column_layout;
  /// Light levels as fractions of the 8-bit full scale (255 DN), before albedo. Not given
  /// in the paper (our choice): dim room light, a bright projector (150 lm, Table 1).
  double ambient_level = 0.10;
  double projector_level = 0.80;
  /// If > 0, projector irradiance scales as (falloff_reference_m / distance)^2; 0 = off.
  double falloff_reference_m = 0.0;
  /// Gaussian sensor noise per pixel and frame, in DN (our choice; the paper gives none).
  /// Samples come from a bank of 2^20 N(0, 1) values drawn once from noise_seed (quantised
  /// to 1/32 sigma, clipped at +-3.97 sigma), read at an offset chosen by each frame's key.
  double noise_sigma_dn = 2.0;
  std::uint64_t noise_seed = 1;
  /// Faces seen from behind are not drawn (meshes are closed, counter-clockwise outside).
  bool cull_back_faces = true;
  /// A point counts as lit when its projector-frame depth is within this of the projector
  /// depth buffer (or the buffer holds its own triangle).
  double shadow_bias_m = 0.002;
  /// Resolution of the projector depth buffer used for the shadow test, relative to the
  /// DMD (our choice for speed: 0.5 gives 2 x 2 DMD pixels per cell, about 1.6 mm at 1 m).
  double shadow_map_scale = 0.5;
  double near_clip_m = 0.05;
  /// Optics, sensor, surface and light effects of a real rig (issue 19), all off by default
  /// (sensor_profile.hpp sets them by name). Projector and surface effects are rendered for
  /// the row codes only: with column_layout they throw std::invalid_argument.
  SensorEffects effects;
};

/// What the projector shows in one frame: a bit of the row code (Eq. 1, geometry.layout), a
/// bit of the column code (column_layout), everything on, or nothing.
enum class ProjectorFrame : std::uint8_t { kRowBit, kColumnBit, kWhite, kBlack };

struct FramePattern {
  ProjectorFrame frame = ProjectorFrame::kRowBit;
  int bit_index = 0;  ///< 0 = MSB; row and column bits only
  bool positive = true;
};

/// One mesh placed in the camera frame (the renderer does not own the mesh).
struct RenderObject {
  const geometry::Mesh* mesh = nullptr;
  Eigen::Isometry3d T_camera_object = Eigen::Isometry3d::Identity();
  double albedo = 0.7;
  /// When set, the object's albedo is this printed pattern (object frame = board frame,
  /// usually on make_checkerboard_mesh()), averaged over 4 x 4 points per camera pixel;
  /// `albedo` is then unused. The renderer does not own it.
  const Checkerboard* checkerboard = nullptr;
};

/// 8-bit mono image, row-major.
struct MonoImage {
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> pixels;
  std::uint8_t at(int x, int y) const { return pixels[static_cast<std::size_t>(y) * width + x]; }
};

class Renderer {
 public:
  explicit Renderer(RendererConfig config);

  const RendererConfig& config() const { return config_; }
  int width() const { return config_.geometry.camera.width; }
  int height() const { return config_.geometry.camera.height; }

  /// Geometry pass for one pose of everything (objects in the camera frame). Incremental:
  /// when only some objects changed since the previous call (same objects, meshes and order,
  /// the others' poses bit-identical, e.g. a moving target before a wall with the head
  /// still), only the screen regions those objects covered or now cover are rasterised and
  /// re-shaded, plus the rows whose projector-shadow lookup falls where they cover the
  /// projector's buffer. The result is bit-identical to a full pass (tested).
  void set_view(const std::vector<RenderObject>& objects);

  /// Frame with bit `bit_index` (0 = MSB) of the pattern, positive or negative, noise drawn
  /// from (noise_seed, noise_key): the same key gives the same image.
  /// `ambient_gain` scales the room light (effects.ambient: its mean over the exposure).
  void shade(int bit_index, bool positive, std::uint64_t noise_key, MonoImage& out,
             float ambient_gain = 1.0f) const;
  /// Any frame (row or column bit, white, black); column and white frames need
  /// RendererConfig::column_layout (std::logic_error otherwise).
  void shade(const FramePattern& pattern, std::uint64_t noise_key, MonoImage& out,
             float ambient_gain = 1.0f) const;

  /// Motion blur: adds weight x the noise-free intensity (DN) of the current view to `sum`
  /// (width*height floats); finish() adds noise and quantises. Row codes only: throws
  /// std::logic_error with calibration patterns (RendererConfig::column_layout).
  void accumulate(int bit_index, bool positive, float weight, std::vector<float>& sum,
                  float ambient_gain = 1.0f) const;
  void finish(const std::vector<float>& sum, std::uint64_t noise_key, MonoImage& out) const;

  // Ground truth of the current view, per camera pixel (row-major). Computed on the first
  // request after set_view() (the per-frame path does not need it).
  /// Camera-frame z of the visible surface, 0 where nothing is seen.
  const std::vector<float>& depth_m() const { return truth().depth_m; }
  /// Index into set_view()'s objects of the visible surface, -1 where nothing is seen.
  const std::vector<std::int16_t>& object_index() const { return truth().object_index; }
  /// Continuous projector row (pixel centres at integers) of the visible surface point when
  /// the projector lights it (inside its coded rows, not shadowed, facing it); NaN otherwise.
  const std::vector<float>& projector_row() const { return truth().projector_row; }
  /// Continuous projector column of the visible surface point when the projector lights it
  /// (on the DMD, not shadowed, facing it; with column_layout: any DMD row, without: coded rows
  /// only); NaN otherwise.
  const std::vector<float>& projector_column() const { return truth().projector_column; }
  /// Code whose rows light the pixel (Eq. 1 layout), -1 when no coded row does.
  const std::vector<std::int16_t>& code() const { return truth().code; }

 private:
  using Box = PixelBox;
  /// Transforms every object's vertices into both views, rebuilds the per-triangle data and
  /// the objects' screen boxes (new_camera_box_, new_shadow_box_).
  void prepare_triangles(const std::vector<RenderObject>& objects);
  /// Rasterises every object into both buffers, only inside the clip boxes (full = whole views;
  /// the buffers are cleared there first).
  void rasterize_all(const std::vector<RenderObject>& objects, const Box& camera_clip,
                     const Box& shadow_clip);
  bool row_reads_shadow_cells(int y, const Box& cells) const;
  struct Truth {
    bool valid = false;
    std::vector<float> depth_m, projector_row, projector_column;
    std::vector<std::int16_t> object_index, code;
  };
  template <bool kWithTruth>
  void compute_row(int y, Truth* truth);
  const Truth& truth() const;
  /// The camera without distortion, widened by a margin when the camera has distortion, and
  /// remap_ for it (empty without distortion).
  geometry::CameraModel make_pinhole_and_remap(const geometry::CameraModel& camera);
  /// The projector without distortion, widened by the margin its distortion needs (the ideal
  /// view the shadow map is rasterised in); sets projector_margin_px_.
  geometry::CameraModel make_projector_pinhole(const geometry::CameraModel& projector);
  template <typename ValueFn>
  void quantise(std::uint64_t noise_key, ValueFn value, MonoImage& out) const;
  /// Light of row bit `bit_index` (0 = MSB) at pinhole pixel i, 0..1 of the projector's: the
  /// sharp bit, or with effects the defocused edge and the black level.
  struct RowBitLight;
  RowBitLight row_bit_light(int bit_index, bool positive) const;
  /// Checks config_.effects and builds their tables (fixed pattern, response curve, normal CDF)
  /// and per-pixel buffers; `pinhole` is the camera view the geometry pass renders.
  void set_up_effects(const geometry::CameraModel& pinhole);

  RendererConfig config_;
  PinholeView camera_view_, shadow_view_;
  geometry::CameraModel projector_;
  double projector_margin_px_ = 0;      ///< ideal projector view = DMD + this margin on each side
  bool calibration_patterns_ = false;   ///< column_layout set: every DMD row lit and tested
  std::vector<std::int16_t> row_code_;  ///< code of each projector row, -1 if uncoded
  std::vector<std::int16_t> column_code_;  ///< code of each projector column (column_layout)
  std::vector<std::int8_t> noise_bank_;    ///< N(0, 1) samples x 32, drawn once from noise_seed
  Eigen::Matrix3f R_projector_camera_;
  Eigen::Vector3f t_projector_camera_m_, projector_centre_camera_m_;
  std::vector<float> ray_x_, ray_y_;                   ///< normalised camera ray per column / row
  std::vector<float> row_z_, row_u_, row_v_, row_qz_;  ///< scratch of compute_row
  std::vector<float> row_inv_distance_;
  DepthBuffer camera_buffer_, projector_buffer_;
  // Per triangle of the current view (ids are cumulative over objects).
  std::vector<Eigen::Vector3f> normal_camera_;
  std::vector<std::int16_t> triangle_object_;
  std::vector<float> triangle_albedo_dn_;             ///< 255 x albedo of the triangle's object
  std::vector<float> triangle_normal_dot_projector_;  ///< n . projector centre (camera frame)
  std::vector<float> triangle_plane_offset_;          ///< n . (a vertex), camera frame
  /// Per object of the current view: its printed pattern (or null) and T_object_camera.
  std::vector<const Checkerboard*> object_checkerboard_;
  std::vector<Eigen::Isometry3d> object_T_object_camera_;
  /// A textured pixel's 4 x 4 sub-samples (calibration patterns only): each one's albedo
  /// (x 255) and the Gray codes (with kCoded) of the row and column that light it, so that a
  /// frame integrates the pattern over the pixel as a sensor does (stripe edges then blur
  /// without the bias that point-sampled stripes get from the lens distortion remap).
  static constexpr int kSubSamples = 16;
  struct SubSamples {
    std::uint16_t row_gray[kSubSamples];
    std::uint16_t column_gray[kSubSamples];
    std::uint8_t albedo[kSubSamples];
  };
  /// Albedo (0..1) of a textured triangle's surface averaged over pinhole pixel (x, y); fills
  /// `sub` when given.
  float textured_albedo(std::int32_t triangle, int x, int y, SubSamples* sub) const;
  std::vector<SubSamples> sub_samples_;       ///< per pinhole pixel (calibration patterns only)
  std::vector<std::uint8_t> is_sub_sampled_;  ///< per pinhole pixel: sub_samples_ is valid
  std::vector<std::vector<Eigen::Vector3f>> camera_vertices_, projector_vertices_;  ///< per object
  // State of the previous set_view() for the incremental pass.
  bool have_last_ = false;
  std::vector<const geometry::Mesh*> last_mesh_;
  std::vector<Eigen::Matrix4d> last_pose_;
  std::vector<double> last_albedo_;
  std::vector<const Checkerboard*> last_checkerboard_;
  std::vector<Box> camera_box_, shadow_box_;          ///< per object, previous view
  std::vector<Box> new_camera_box_, new_shadow_box_;  ///< per object, current view
  /// Per camera pixel: the shadow-map cell (column, row) its last shadow test read; -1: none.
  std::vector<std::int16_t> shadow_cell_u_, shadow_cell_v_;
  // Per pixel, for shading: intensity = base + gain * bit.
  std::vector<float> base_dn_, gain_dn_;
  /// Gray code of the row (column) code lighting each pixel, with kCoded set; 0 where no
  /// coded row (column) lights it.
  std::vector<std::uint16_t> gray_, column_gray_;
  mutable Truth truth_;  ///< filled lazily by truth()
  /// With lens distortion: per camera pixel, the four pinhole pixels (camera_view_) around the
  /// ideal point it sees, bilinear weights, and the nearest of them (for the ground truth).
  struct RemapEntry {
    std::uint32_t index[4];
    float weight[4];
    std::uint32_t nearest;
  };
  std::vector<RemapEntry> remap_;
  mutable Truth truth_camera_;  ///< truth_ remapped to the camera's pixels (distortion only)
  // Sensor effects (config_.effects), sized only when the effect is on.
  bool pattern_effects_ = false;       ///< effects.changes_pattern_light()
  std::vector<float> code_position_;   ///< per pinhole pixel: continuous code (defocus)
  std::vector<float> inv_blur_codes_;  ///< per pinhole pixel: 1 / edge blur sigma, in codes
  std::vector<float> phi_table_;       ///< standard normal CDF on [0, 4), 128 per unit
  std::vector<Eigen::Isometry3f> object_T_object_camera_f_;  ///< texture lookup
  bool camera_response_ = false;                             ///< !effects.camera.is_ideal()
  std::vector<float> prnu_gain_, dsnu_dn_;                   ///< per camera pixel, fixed pattern
  float dn_per_electron_ = 0, read_variance_dn2_ = 0;
  std::vector<float> gamma_table_;  ///< 255 (s / 255)^(1 / gamma) at s = k / 4, k = 0..1024
  // Camera defocus (effects.lens): per camera pixel a sigma level, Gaussian kernels per level.
  static constexpr int kBlurRadius = 3;
  static constexpr int kBlurLevelsPerPixel = 16;
  static constexpr int kBlurLevels = 2 * kBlurLevelsPerPixel + 1;  ///< sigma 0 .. 2 px
  std::vector<std::uint8_t> blur_level_;                           ///< empty: no camera defocus
  std::vector<float> blur_weights_;
  mutable std::vector<float> blur_in_, blur_tmp_;  ///< per-frame scratch of quantise()
  void update_blur_levels();
  /// Blurs blur_in_ in place by each pixel's level.
  void defocus_camera_image() const;
};

/// The noise key of a frame: mixes the frame index so consecutive frames are independent.
std::uint64_t frame_noise_key(std::uint64_t frame_index);

}  // namespace avs::sim
