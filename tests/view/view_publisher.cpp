// A small graph for the `avs view` test: publishes /object/pose (PoseStamped, 100 Hz) and
// /depth/image (32FC1 160x120, 100 Hz) whose every value is a function of the message index
// i (stamp.sec = 100 + i), so that the Node client can check each decoded message exactly:
//   pose:  frame "camera_optical_frame", position (i * 0.001, -i * 0.5, 1.25), orientation
//          (0, 0, 0.6, 0.8)
//   image: frame "camera_optical_frame", pixel (x, y) = (i % 1000) + x * 0.5 + y * 0.25
//   /head/joint_states: joints "pan", "tilt" at positions (i * 0.001, -(i * 0.0005)) rad
// and, for the page's other panels (stamp.sec = 100 + i on each):
//   /target: centroid (40 + i % 80, 30 + i % 60) px, valid
//   /head/torque_command: "pan", "tilt" at (0.01 * (i % 50), -0.2) N m
//   /sim/ground_truth: pose_camera = the pose moved by +2 mm in x (so the pose error is 2 mm,
//                      0 deg), object "target"
//   /timing: stages "decode" 0.75 ms and "matching" 0.5 ms
//   /object/scene_points: a 20 x 20 grid, 5 mm apart, in the plane z = 1.3 m
//   /object/model_points: 60 points on a 30 mm circle centred at (0.02 sin(0.1 i), 0, 1.25) m
// With --ephemeral it publishes std_msgs/String on /view_test/ephemeral instead, so that the
// test can make a channel appear and disappear. Runs until SIGTERM/SIGINT.
// usage: view_test_publisher DOMAIN [--ephemeral]
#include <atomic>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "avs/msg/convert.hpp"
#include "avs/msg/type_support.hpp"
#include "avs/runtime/dds.hpp"
#include "avs/runtime/qos.hpp"
#include "avs/runtime/sample.hpp"

namespace {

using namespace avs;
namespace dds = runtime::dds;

std::atomic<bool> g_stop{false};
void on_signal(int) {
  g_stop = true;
}

template <class T>
struct Output {
  dds::Topic topic;
  dds::Writer writer;
  Output(const dds::Participant& p, const char* name)
      : topic(p, msg::TypeSupport<T>::descriptor(), name, runtime::QosProfile{}),
        writer(p, topic, runtime::QosProfile{}) {}
};

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: %s DOMAIN [--ephemeral]\n", argv[0]);
    return 2;
  }
  const int domain = std::atoi(argv[1]);
  const bool ephemeral = argc > 2 && std::strcmp(argv[2], "--ephemeral") == 0;
  std::signal(SIGTERM, on_signal);
  std::signal(SIGINT, on_signal);
  const dds::Participant participant(domain);
  if (ephemeral) {
    Output<msgs::std_msgs::String> out(participant, "rt/view_test/ephemeral");
    for (int i = 0; !g_stop; ++i) {
      auto s = runtime::make_sample<msgs::std_msgs::String>();
      runtime::set_string(s->data, "hello " + std::to_string(i));
      out.writer.write(s.get());
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    return 0;
  }
  Output<msgs::geometry_msgs::PoseStamped> pose_out(participant, "rt/object/pose");
  Output<msgs::sensor_msgs::Image> image_out(participant, "rt/depth/image");
  Output<msgs::sensor_msgs::JointState> joints_out(participant, "rt/head/joint_states");
  Output<msgs::avs_msgs::TargetObservation> target_out(participant, "rt/target");
  Output<msgs::avs_msgs::JointTorqueCommand> torque_out(participant, "rt/head/torque_command");
  Output<msgs::avs_msgs::GroundTruth> truth_out(participant, "rt/sim/ground_truth");
  Output<msgs::avs_msgs::StageTiming> timing_out(participant, "rt/timing");
  Output<msgs::sensor_msgs::PointCloud2> scene_out(participant, "rt/object/scene_points");
  Output<msgs::sensor_msgs::PointCloud2> model_out(participant, "rt/object/model_points");
  constexpr std::uint32_t kWidth = 160, kHeight = 120;
  auto next = std::chrono::steady_clock::now();
  for (std::uint32_t i = 0; !g_stop; ++i) {
    auto pose = runtime::make_sample<msgs::geometry_msgs::PoseStamped>();
    pose->header.stamp.sec = static_cast<std::int32_t>(100 + i);
    runtime::set_string(pose->header.frame_id, "camera_optical_frame");
    pose->pose.position.x = i * 0.001;
    pose->pose.position.y = -(i * 0.5);
    pose->pose.position.z = 1.25;
    pose->pose.orientation.z = 0.6;
    pose->pose.orientation.w = 0.8;
    pose_out.writer.write(pose.get());

    auto image = runtime::make_sample<msgs::sensor_msgs::Image>();
    image->header.stamp.sec = static_cast<std::int32_t>(100 + i);
    runtime::set_string(image->header.frame_id, "camera_optical_frame");
    runtime::set_string(image->encoding, "32FC1");
    image->width = kWidth;
    image->height = kHeight;
    image->step = kWidth * 4;
    runtime::resize_sequence(image->data, kWidth * kHeight * 4);
    for (std::uint32_t y = 0; y < kHeight; ++y) {
      for (std::uint32_t x = 0; x < kWidth; ++x) {
        const float v = static_cast<float>(i % 1000) + static_cast<float>(x) * 0.5f +
                        static_cast<float>(y) * 0.25f;
        std::memcpy(image->data._buffer + (y * kWidth + x) * 4, &v, 4);
      }
    }
    image_out.writer.write(image.get());

    auto joints = runtime::make_sample<msgs::sensor_msgs::JointState>();
    joints->header.stamp.sec = static_cast<std::int32_t>(100 + i);
    runtime::resize_sequence(joints->name, 2);
    runtime::set_string(joints->name._buffer[0], "pan");
    runtime::set_string(joints->name._buffer[1], "tilt");
    runtime::resize_sequence(joints->position, 2);
    joints->position._buffer[0] = i * 0.001;
    joints->position._buffer[1] = -(i * 0.0005);
    joints_out.writer.write(joints.get());

    const auto stamp = pose->header.stamp;
    auto target = runtime::make_sample<msgs::avs_msgs::TargetObservation>();
    target->header.stamp = stamp;
    runtime::set_string(target->header.frame_id, "camera_optical_frame");
    target->centroid_x_px = 40 + i % 80;
    target->centroid_y_px = 30 + i % 60;
    target->mean_depth_m = 1.25;
    target->valid = true;
    target_out.writer.write(target.get());

    auto torque = runtime::make_sample<msgs::avs_msgs::JointTorqueCommand>();
    torque->header.stamp = stamp;
    runtime::resize_sequence(torque->name, 2);
    runtime::set_string(torque->name._buffer[0], "pan");
    runtime::set_string(torque->name._buffer[1], "tilt");
    runtime::resize_sequence(torque->torque_nm, 2);
    torque->torque_nm._buffer[0] = 0.01 * (i % 50);
    torque->torque_nm._buffer[1] = -0.2;
    torque_out.writer.write(torque.get());

    auto truth = runtime::make_sample<msgs::avs_msgs::GroundTruth>();
    truth->header.stamp = stamp;
    runtime::set_string(truth->header.frame_id, "world");
    runtime::set_string(truth->object_name, "target");
    truth->pose_camera = pose->pose;
    truth->pose_camera.position.x += 0.002;
    truth->pose_world.orientation.w = 1;
    truth_out.writer.write(truth.get());

    for (const auto& [stage, ms] : {std::pair{"decode", 0.75}, std::pair{"matching", 0.5}}) {
      auto timing = runtime::make_sample<msgs::avs_msgs::StageTiming>();
      timing->header.stamp = stamp;
      runtime::set_string(timing->header.frame_id, "camera_optical_frame");
      runtime::set_string(timing->stage, stage);
      timing->processing_ms = ms;
      timing_out.writer.write(timing.get());
    }

    std::vector<Eigen::Vector3f> grid;
    for (int v = 0; v < 20; ++v) {
      for (int u = 0; u < 20; ++u) grid.emplace_back(0.005f * (u - 10), 0.005f * (v - 10), 1.3f);
    }
    auto scene = runtime::make_sample<msgs::sensor_msgs::PointCloud2>();
    scene->header.stamp = stamp;
    runtime::set_string(scene->header.frame_id, "camera_optical_frame");
    msg::write_xyz_cloud(grid, *scene);
    scene_out.writer.write(scene.get());
    std::vector<Eigen::Vector3f> circle;
    const double centre_x = 0.02 * std::sin(0.1 * i);
    for (int k = 0; k < 60; ++k) {
      const double a = 2 * M_PI * k / 60;
      circle.emplace_back(static_cast<float>(centre_x + 0.03 * std::cos(a)),
                          static_cast<float>(0.03 * std::sin(a)), 1.25f);
    }
    auto model = runtime::make_sample<msgs::sensor_msgs::PointCloud2>();
    model->header.stamp = stamp;
    runtime::set_string(model->header.frame_id, "camera_optical_frame");
    msg::write_xyz_cloud(circle, *model);
    model_out.writer.write(model.get());
    next += std::chrono::milliseconds(10);
    std::this_thread::sleep_until(next);
  }
  return 0;
}
