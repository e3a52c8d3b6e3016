// The rig's frame names, as every stamped message and /tf, /tf_static use them (ROS 2 REP 105
// / REP 103 style; docs/view.md draws the tree):
//   world -> pan_link -> tilt_link -> camera_optical_frame -> object
//                                                          -> projector_optical_frame
// world: ours (head_kinematics.hpp: origin on the pan axis, Z up, X the viewing direction at
// q = 0). pan_link: rotated by the pan joint. tilt_link: rotated by the tilt joint.
// camera_optical_frame: x right, y down, z forward (the camera model's frame, the frame of
// /depth/image and /object/pose). projector_optical_frame: the projector's, same axes.
#pragma once

namespace avs::geometry::frame {

inline constexpr const char* kWorld = "world";
inline constexpr const char* kPanLink = "pan_link";
inline constexpr const char* kTiltLink = "tilt_link";
inline constexpr const char* kCameraOptical = "camera_optical_frame";
inline constexpr const char* kProjectorOptical = "projector_optical_frame";
inline constexpr const char* kObject = "object";

}  // namespace avs::geometry::frame
