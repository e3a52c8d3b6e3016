#include "avs/msg/convert.hpp"

#include <cmath>
#include <cstring>
#include <stdexcept>

#include "avs/runtime/sample.hpp"

namespace avs::msg {

Eigen::Isometry3d to_isometry(const msgs::geometry_msgs::Pose& p) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() =
      Eigen::Quaterniond(p.orientation.w, p.orientation.x, p.orientation.y, p.orientation.z)
          .normalized()
          .toRotationMatrix();
  T.translation() = Eigen::Vector3d(p.position.x, p.position.y, p.position.z);
  return T;
}

void to_pose(const Eigen::Isometry3d& T, msgs::geometry_msgs::Pose& pose) {
  const Eigen::Quaterniond q(T.linear());
  pose.position.x = T.translation().x();
  pose.position.y = T.translation().y();
  pose.position.z = T.translation().z();
  pose.orientation.x = q.x();
  pose.orientation.y = q.y();
  pose.orientation.z = q.z();
  pose.orientation.w = q.w();
}

bool is_finite(const msgs::geometry_msgs::Pose& p) {
  const double v[7] = {p.position.x,    p.position.y,    p.position.z,   p.orientation.x,
                       p.orientation.y, p.orientation.z, p.orientation.w};
  for (const double x : v) {
    if (!std::isfinite(x)) return false;
  }
  return v[3] != 0 || v[4] != 0 || v[5] != 0 || v[6] != 0;
}

void set_xyz_fields(msgs::sensor_msgs::PointCloud2& cloud) {
  runtime::resize_sequence(cloud.fields, 3);
  const char* names[3] = {"x", "y", "z"};
  for (std::uint32_t i = 0; i < 3; ++i) {
    auto& field = cloud.fields._buffer[i];
    runtime::set_string(field.name, names[i]);
    field.offset = 4 * i;
    field.datatype = sensor_msgs_msg_dds__PointField_Constants_FLOAT32;
    field.count = 1;
  }
  cloud.is_bigendian = false;
  cloud.point_step = 12;
}

void write_xyz_cloud(std::span<const Eigen::Vector3f> points,
                     msgs::sensor_msgs::PointCloud2& cloud) {
  set_xyz_fields(cloud);
  cloud.height = 1;
  cloud.width = static_cast<std::uint32_t>(points.size());
  cloud.row_step = 12 * cloud.width;
  cloud.is_dense = true;
  runtime::resize_sequence(cloud.data, cloud.row_step);
  for (std::size_t i = 0; i < points.size(); ++i) {
    std::memcpy(cloud.data._buffer + 12 * i, points[i].data(), 12);
    if (!points[i].allFinite()) cloud.is_dense = false;
  }
}

std::optional<std::vector<Eigen::Vector3d>> read_xyz_cloud(
    const msgs::sensor_msgs::PointCloud2& cloud, std::string* why) {
  auto reject = [why](const std::string& text) -> std::optional<std::vector<Eigen::Vector3d>> {
    if (why != nullptr) *why = "PointCloud2: " + text;
    return std::nullopt;
  };
  std::int64_t offset[3] = {-1, -1, -1};
  const char* names[3] = {"x", "y", "z"};
  for (std::uint32_t i = 0; i < cloud.fields._length; ++i) {
    const auto& f = cloud.fields._buffer[i];
    for (int a = 0; a < 3; ++a) {
      if (runtime::get_string(f.name) == names[a] &&
          f.datatype == sensor_msgs_msg_dds__PointField_Constants_FLOAT32) {
        offset[a] = f.offset;
      }
    }
  }
  if (offset[0] < 0 || offset[1] < 0 || offset[2] < 0 || cloud.is_bigendian) {
    return reject("expected little-endian FLOAT32 x, y, z fields");
  }
  for (const std::int64_t o : offset) {
    if (o + 4 > static_cast<std::int64_t>(cloud.point_step)) {
      return reject("field at offset " + std::to_string(o) + " outside point_step " +
                    std::to_string(cloud.point_step));
    }
  }
  const std::uint64_t count = static_cast<std::uint64_t>(cloud.width) * cloud.height;
  if (count * cloud.point_step > cloud.data._length) {
    return reject(std::to_string(cloud.width) + "x" + std::to_string(cloud.height) + " points of " +
                  std::to_string(cloud.point_step) + " bytes, but " +
                  std::to_string(cloud.data._length) + " bytes of data");
  }
  std::vector<Eigen::Vector3d> points;
  points.reserve(count);
  for (std::uint64_t i = 0; i < count; ++i) {
    const std::uint8_t* p = cloud.data._buffer + i * cloud.point_step;
    float xyz[3];
    for (int a = 0; a < 3; ++a) std::memcpy(&xyz[a], p + offset[a], 4);
    if (std::isfinite(xyz[0]) && std::isfinite(xyz[1]) && std::isfinite(xyz[2])) {
      points.emplace_back(xyz[0], xyz[1], xyz[2]);
    }
  }
  return points;
}

std::optional<JointReading> find_joint(const msgs::sensor_msgs::JointState& state,
                                       std::string_view name) {
  for (std::uint32_t i = 0; i < state.name._length && i < state.position._length; ++i) {
    if (runtime::get_string(state.name._buffer[i]) != name) continue;
    return JointReading{state.position._buffer[i],
                        i < state.velocity._length ? state.velocity._buffer[i] : 0.0};
  }
  return std::nullopt;
}

std::vector<std::string> parse_name_list(std::string_view list, std::size_t count,
                                         std::string_view parameter) {
  std::vector<std::string> names;
  bool empty = false;
  std::size_t start = 0;
  for (;;) {
    const std::size_t comma = list.find(',', start);
    std::string_view name =
        list.substr(start, comma == std::string_view::npos ? comma : comma - start);
    const std::size_t first = name.find_first_not_of(" \t");
    name = first == std::string_view::npos
               ? std::string_view{}
               : name.substr(first, name.find_last_not_of(" \t") - first + 1);
    empty = empty || name.empty();
    names.emplace_back(name);
    if (comma == std::string_view::npos) break;
    start = comma + 1;
  }
  if ((count != 0 && names.size() != count) || empty) {
    const std::string how_many = count == 0 ? "one or more" : std::to_string(count);
    throw std::invalid_argument("parameter '" + std::string(parameter) + "' needs " + how_many +
                                " comma-separated names, got '" + std::string(list) + "'");
  }
  return names;
}

}  // namespace avs::msg
