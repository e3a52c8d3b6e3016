// Topic types <-> the cores' types, written once: poses as Eigen::Isometry3d, xyz point clouds,
// joints by name, lists of names in parameters. Components use these instead of their own
// copies; none of them throws on a bad sample (they return what is wrong).
#pragma once

#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Geometry>

#include "avs/msg/type_support.hpp"

namespace avs::msg {

/// geometry_msgs/Pose -> rigid transform (the quaternion normalised).
Eigen::Isometry3d to_isometry(const msgs::geometry_msgs::Pose& pose);
/// Rigid transform -> geometry_msgs/Pose.
void to_pose(const Eigen::Isometry3d& T, msgs::geometry_msgs::Pose& pose);
/// All seven numbers finite and the quaternion not zero.
bool is_finite(const msgs::geometry_msgs::Pose& pose);

/// Fills an unorganised cloud (height 1) of little-endian FLOAT32 x, y, z (point_step 12).
void write_xyz_cloud(std::span<const Eigen::Vector3f> points,
                     msgs::sensor_msgs::PointCloud2& cloud);
/// Declares the x, y, z FLOAT32 fields at offsets 0, 4, 8 (point_step 12), for a cloud whose
/// data the caller writes (organised clouds).
void set_xyz_fields(msgs::sensor_msgs::PointCloud2& cloud);
/// The finite x, y, z points of a cloud with little-endian FLOAT32 x, y, z fields, or nullopt
/// with `why` (missing fields, fields outside point_step, data shorter than the layout).
std::optional<std::vector<Eigen::Vector3d>> read_xyz_cloud(
    const msgs::sensor_msgs::PointCloud2& cloud, std::string* why = nullptr);

/// One joint of a sensor_msgs/JointState, found by name.
struct JointReading {
  double position = 0;  ///< rad (or m for a prismatic joint)
  double velocity = 0;  ///< 0 when the message has no velocity for it
};
std::optional<JointReading> find_joint(const msgs::sensor_msgs::JointState& state,
                                       std::string_view name);

/// "pan, tilt" -> {"pan", "tilt"}: exactly `count` (0: one or more) non-empty comma-separated
/// names, blanks around each trimmed; throws std::invalid_argument naming `parameter` otherwise
/// (a configuration error).
std::vector<std::string> parse_name_list(std::string_view list, std::size_t count,
                                         std::string_view parameter);

}  // namespace avs::msg
