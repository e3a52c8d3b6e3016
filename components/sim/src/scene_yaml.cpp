// Scene YAML adapter (see scene_yaml.hpp; format in docs/sim.md).
#include "avs/sim/scene_yaml.hpp"

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <numbers>
#include <sstream>
#include <stdexcept>

#include <yaml-cpp/yaml.h>

#include "avs/geometry/builtin_models.hpp"
#include "avs/geometry/primitives.hpp"
#include "avs/runtime/text.hpp"
#include "avs/runtime/yaml_checks.hpp"
#include "avs/sim/sensor_profile.hpp"

namespace avs::sim {
namespace {

class Parser {
 public:
  Parser(std::string name, std::string base_dir, std::string models_dir)
      : name_(std::move(name)),
        base_dir_(std::move(base_dir)),
        models_dir_(std::move(models_dir)) {}

  [[noreturn]] void fail(const YAML::Node& node, const std::string& what) const {
    throw std::runtime_error(runtime::yaml_location(name_, node.Mark()) + ": " + what);
  }

  template <typename T>
  T get(const YAML::Node& map, const std::string& key, const T& fallback) const {
    const YAML::Node node = map[key];
    if (!node) return fallback;
    try {
      return node.as<T>();
    } catch (const YAML::Exception&) {
      fail(node, "'" + key + "' has the wrong type");
    }
  }

  Eigen::Vector3d vec3(const YAML::Node& map, const std::string& key,
                       const Eigen::Vector3d& fallback) const {
    const YAML::Node node = map[key];
    if (!node) return fallback;
    if (!node.IsSequence() || node.size() != 3) fail(node, "'" + key + "' must be [x, y, z]");
    Eigen::Vector3d v;
    for (int i = 0; i < 3; ++i) v[i] = scalar(node[i], key);
    return v;
  }

  double scalar(const YAML::Node& node, const std::string& key) const {
    try {
      return node.as<double>();
    } catch (const YAML::Exception&) {
      fail(node, "'" + key + "' must hold numbers");
    }
  }

  /// position_m plus rpy_deg [roll, pitch, yaw] (R = Rz(yaw) Ry(pitch) Rx(roll)) or
  /// quaternion_wxyz.
  Eigen::Isometry3d pose(const YAML::Node& map, const Eigen::Isometry3d& fallback) const {
    Eigen::Isometry3d T = fallback;
    T.translation() = vec3(map, "position_m", fallback.translation());
    if (map["rpy_deg"] && map["quaternion_wxyz"]) {
      fail(map, "give either rpy_deg or quaternion_wxyz, not both");
    }
    if (map["rpy_deg"]) {
      const Eigen::Vector3d rpy =
          vec3(map, "rpy_deg", Eigen::Vector3d::Zero()) * std::numbers::pi / 180.0;
      T.linear() = (Eigen::AngleAxisd(rpy[2], Eigen::Vector3d::UnitZ()) *
                    Eigen::AngleAxisd(rpy[1], Eigen::Vector3d::UnitY()) *
                    Eigen::AngleAxisd(rpy[0], Eigen::Vector3d::UnitX()))
                       .toRotationMatrix();
    } else if (const YAML::Node q = map["quaternion_wxyz"]) {
      if (!q.IsSequence() || q.size() != 4) fail(q, "quaternion_wxyz must be [w, x, y, z]");
      Eigen::Quaterniond quat(scalar(q[0], "quaternion_wxyz"), scalar(q[1], "quaternion_wxyz"),
                              scalar(q[2], "quaternion_wxyz"), scalar(q[3], "quaternion_wxyz"));
      if (quat.norm() < 1e-9) fail(q, "quaternion of zero length");
      T.linear() = quat.normalized().toRotationMatrix();
    }
    return T;
  }

  std::shared_ptr<const Trajectory> trajectory(const YAML::Node& node) const {
    if (!node) return std::make_shared<StaticTrajectory>(ManipulatorMotionConfig::default_start());
    const std::string type = get<std::string>(node, "type", "static");
    try {
      if (type == "static") {
        return std::make_shared<StaticTrajectory>(
            pose(node, ManipulatorMotionConfig::default_start()));
      }
      if (type == "waypoints") return waypoints(node);
      if (type == "manipulator") return manipulator(node);
      if (type == "lateral_swing") {
        LateralSwingConfig c;
        c.T_world_object_centre = pose(node, c.T_world_object_centre);
        c.axis_world = vec3(node, "axis", c.axis_world);
        c.amplitude_m = get(node, "amplitude_m", c.amplitude_m);
        c.peak_speed_mps = get(node, "peak_speed_mps", c.peak_speed_mps);
        c.start_time_s = get(node, "start_time_s", c.start_time_s);
        return std::make_shared<LateralSwingTrajectory>(c);
      }
    } catch (const std::invalid_argument& e) {
      fail(node, e.what());
    }
    fail(node["type"],
         "unknown trajectory type '" + type + "' (static, waypoints, manipulator, lateral_swing)");
  }

  std::shared_ptr<const Trajectory> waypoints(const YAML::Node& node) const {
    const YAML::Node points = node["points"];
    if (!points || !points.IsSequence()) fail(node, "waypoints trajectory needs a 'points' list");
    std::vector<Waypoint> list;
    Eigen::Isometry3d previous = ManipulatorMotionConfig::default_start();
    for (const YAML::Node& p : points) {
      if (!p["t_s"]) fail(p, "waypoint without t_s");
      const Eigen::Isometry3d T = pose(p, previous);
      list.push_back({get(p, "t_s", 0.0), T.translation(), Eigen::Quaterniond(T.linear())});
      previous = T;
    }
    return std::make_shared<WaypointTrajectory>(list, get(node, "ease", false),
                                                get(node, "loop", false));
  }

  std::shared_ptr<const Trajectory> manipulator(const YAML::Node& node) const {
    ManipulatorMotionConfig c;
    c.T_world_object_start = pose(node, c.T_world_object_start);
    c.p_object_pivot_world_m = vec3(node, "pivot_offset_m", c.p_object_pivot_world_m);
    c.start_time_s = get(node, "start_time_s", c.start_time_s);
    c.duration_s = get(node, "duration_s", c.duration_s);
    if (const YAML::Node segments = node["segments"]) {
      c.segments.clear();
      for (const YAML::Node& s : segments) {
        c.segments.push_back({vec3(s, "axis", Eigen::Vector3d::UnitZ()),
                              get(s, "angle_deg", 0.0) * std::numbers::pi / 180.0});
      }
    }
    return std::make_shared<ManipulatorTrajectory>(c);
  }

  std::shared_ptr<const geometry::Mesh> mesh(const YAML::Node& node) {
    const int sources = (node["model"] ? 1 : 0) + (node["mesh"] ? 1 : 0) + (node["plane"] ? 1 : 0);
    if (sources != 1) fail(node, "an object needs exactly one of 'model', 'mesh' or 'plane'");
    geometry::Mesh mesh;
    std::string source_path;
    if (const YAML::Node plane = node["plane"]) {
      mesh = geometry::make_plane(get(plane, "width_m", 4.0), get(plane, "height_m", 3.0),
                                  get(plane, "divisions", 1));
    } else {
      std::string path;
      if (node["model"]) {
        const std::string model = get<std::string>(node, "model", "");
        path = (models_dir_.empty() ? geometry::default_models_dir() : models_dir_) + "/" + model +
               ".ply";
      } else {
        path = get<std::string>(node, "mesh", "");
        if (!std::filesystem::path(path).is_absolute()) path = base_dir_ + "/" + path;
      }
      source_path = path;
      const auto cached = cache_.find(path);
      if (cached != cache_.end() && !node["scale"]) return cached->second;
      try {
        mesh = geometry::load_mesh(path);
      } catch (const std::runtime_error& e) {
        fail(node, e.what());
      }
    }
    const double scale = get(node, "scale", 1.0);
    if (scale != 1.0) {
      for (Eigen::Vector3f& v : mesh.vertices) v *= static_cast<float>(scale);
    }
    auto shared = std::make_shared<const geometry::Mesh>(std::move(mesh));
    if (!node["plane"] && !node["scale"]) cache_[source_path] = shared;
    return shared;
  }

  void sensor(const YAML::Node& node, SimulatorConfig& c) const {
    if (!node) return;
    RendererConfig& r = c.renderer;
    // A named profile first (issue 19), so that the keys below override single values of it.
    if (const YAML::Node profile = node["profile"]) {
      try {
        apply_sensor_profile(parse_sensor_profile(profile.as<std::string>()), c);
      } catch (const std::exception& e) {
        fail(profile, e.what());
      }
    }
    effects(node, r.effects);
    r.ambient_level = get(node, "ambient_level", r.ambient_level);
    r.projector_level = get(node, "projector_level", r.projector_level);
    r.falloff_reference_m = get(node, "falloff_reference_m", r.falloff_reference_m);
    r.noise_sigma_dn = get(node, "noise_sigma_dn", r.noise_sigma_dn);
    r.noise_seed = get(node, "noise_seed", r.noise_seed);
    r.cull_back_faces = get(node, "cull_back_faces", r.cull_back_faces);
    r.shadow_bias_m = get(node, "shadow_bias_m", r.shadow_bias_m);
    r.near_clip_m = get(node, "near_clip_m", r.near_clip_m);
    c.frame_rate_hz = get(node, "frame_rate_hz", c.frame_rate_hz);
    c.exposure_s = get(node, "exposure_s", c.exposure_s);
    c.motion_blur_samples = get(node, "motion_blur_samples", c.motion_blur_samples);
  }

  /// sensor.projector, .lens, .camera, .ambient_flicker and .surface: single effect values.
  void effects(const YAML::Node& node, SensorEffects& e) const {
    if (const YAML::Node p = node["projector"]) {
      e.projector.black_level = get(p, "black_level", e.projector.black_level);
      e.projector.aperture_m = get(p, "aperture_m", e.projector.aperture_m);
      e.projector.focus_distance_m = get(p, "focus_distance_m", e.projector.focus_distance_m);
      e.projector.focused_blur_px = get(p, "focused_blur_px", e.projector.focused_blur_px);
    }
    if (const YAML::Node l = node["lens"]) {
      e.lens.f_number = get(l, "f_number", e.lens.f_number);
      e.lens.focus_distance_m = get(l, "focus_distance_m", e.lens.focus_distance_m);
      e.lens.focal_length_m = get(l, "focal_length_m", e.lens.focal_length_m);
    }
    if (const YAML::Node m = node["camera"]) {
      e.camera.full_well_e = get(m, "full_well_e", e.camera.full_well_e);
      e.camera.read_noise_e = get(m, "read_noise_e", e.camera.read_noise_e);
      e.camera.prnu_fraction = get(m, "prnu_fraction", e.camera.prnu_fraction);
      e.camera.dsnu_dn = get(m, "dsnu_dn", e.camera.dsnu_dn);
      e.camera.gamma = get(m, "gamma", e.camera.gamma);
    }
    if (const YAML::Node a = node["ambient_flicker"]) {
      e.ambient.modulation = get(a, "modulation", e.ambient.modulation);
      e.ambient.frequency_hz = get(a, "frequency_hz", e.ambient.frequency_hz);
    }
    if (const YAML::Node f = node["surface"]) {
      e.surface.specular_fraction = get(f, "specular_fraction", e.surface.specular_fraction);
      e.surface.shininess = get(f, "shininess", e.surface.shininess);
      e.surface.texture_contrast = get(f, "texture_contrast", e.surface.texture_contrast);
      e.surface.texture_scale_m = get(f, "texture_scale_m", e.surface.texture_scale_m);
    }
    if (const std::string problem = e.problem(); !problem.empty()) fail(node, problem);
  }

  void head(const YAML::Node& node, HeadConfig& h) const {
    if (!node) return;
    h.p_world_pan_m = vec3(node, "p_world_pan_m", h.p_world_pan_m);
    h.p_pan_tilt_m = vec3(node, "p_pan_tilt_m", h.p_pan_tilt_m);
    h.p_tilt_camera_m = vec3(node, "p_tilt_camera_m", h.p_tilt_camera_m);
  }

 private:
  std::string name_, base_dir_, models_dir_;
  std::map<std::string, std::shared_ptr<const geometry::Mesh>> cache_;
};

SceneFile parse_root(const std::string& yaml_text, const std::string& name_for_errors,
                     const std::string& base_dir, const std::string& models_dir) {
  const YAML::Node root = runtime::yaml_parse(yaml_text, name_for_errors);
  Parser parser(name_for_errors, base_dir, models_dir);
  if (!root.IsMap()) parser.fail(root, "a scene file is a map with an 'objects' list");
  SceneFile file;
  parser.sensor(root["sensor"], file.config);
  parser.head(root["head"], file.config.head);
  const YAML::Node objects = root["objects"];
  if (!objects || !objects.IsSequence()) parser.fail(root, "missing 'objects' list");
  for (const YAML::Node& node : objects) {
    if (!node.IsMap()) parser.fail(node, "an object is a map (name, model/mesh/plane, ...)");
    SceneObject object;
    object.name =
        parser.get<std::string>(node, "name", "object" + std::to_string(file.scene.objects.size()));
    if (file.scene.find(object.name) >= 0)
      parser.fail(node, "duplicate object name '" + object.name + "'");
    object.mesh = parser.mesh(node);
    object.albedo = parser.get(node, "albedo", object.albedo);
    if (!(object.albedo >= 0 && object.albedo <= 1)) parser.fail(node, "albedo must be in [0, 1]");
    object.trajectory = parser.trajectory(node["trajectory"]);
    file.scene.objects.push_back(std::move(object));
  }
  return file;
}

}  // namespace

SceneFile parse_scene(const std::string& yaml_text, const std::string& name_for_errors,
                      const std::string& base_dir, const std::string& models_dir) {
  try {
    return parse_root(yaml_text, name_for_errors, base_dir, models_dir);
  } catch (const YAML::Exception& e) {
    throw std::runtime_error(runtime::yaml_error_message(name_for_errors, e));
  }
}

SceneFile load_scene(const std::string& path, const std::string& models_dir) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot open scene file");
  std::stringstream text;
  text << in.rdbuf();
  const std::string dir = std::filesystem::path(path).parent_path().string();
  return parse_scene(text.str(), path, dir.empty() ? "." : dir, models_dir);
}

}  // namespace avs::sim
