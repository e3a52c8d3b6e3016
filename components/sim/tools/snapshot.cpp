// avs_sim_snapshot SCENE.yaml OUT_DIR [TIME_S] [PROFILES_PNG]
// Renders the 2n pattern frames of one cycle at TIME_S (default 0) with the head aimed at
// the first object, and writes OUT_DIR/frame_XX.pgm plus OUT_DIR/depth.pgm (near = bright).
// With PROFILES_PNG, also the figure of docs/sim.md's sensor profiles: the image centre
// (160 x 160 pixels, shown 2x) of three frames (bit 5 positive, the last bit positive and
// negative), rendered in the ideal profile (top row) and the realistic one (bottom row).
#include <algorithm>
#include <cstdlib>
#include <exception>
#include <fstream>
#include <iostream>
#include <string>

#include "avs/decode/png_io.hpp"
#include "avs/sim/scene_yaml.hpp"
#include "avs/sim/sensor_profile.hpp"
#include "avs/sim/simulator.hpp"

namespace {

void write_pgm(const std::string& path, int width, int height, const std::uint8_t* pixels) {
  std::ofstream out(path, std::ios::binary);
  out << "P5\n" << width << ' ' << height << "\n255\n";
  out.write(reinterpret_cast<const char*>(pixels), static_cast<std::streamsize>(width) * height);
  if (!out) throw std::runtime_error(path + ": write failed");
}

/// The profiles figure (see the file comment); frame indices are those of the cycle at t.
void write_profiles_png(const std::string& path, const avs::sim::SceneFile& file, double t,
                        const avs::sim::HeadState& head) {
  constexpr int kCrop = 160, kZoom = 2;
  const int bits = file.config.renderer.geometry.layout.bit_count;
  const int frames[3] = {2 * 5, 2 * (bits - 1), 2 * (bits - 1) + 1};
  avs::decode::GrayImage8 figure;
  figure.width = 3 * kCrop * kZoom + 2 * 4;
  figure.height = 2 * kCrop * kZoom + 4;
  figure.pixels.assign(static_cast<std::size_t>(figure.width) * figure.height, 255);
  for (int row = 0; row < 2; ++row) {
    avs::sim::SimulatorConfig config = file.config;
    avs::sim::apply_sensor_profile(
        row == 0 ? avs::sim::SensorProfile::kIdeal : avs::sim::SensorProfile::kRealistic, config);
    avs::sim::Simulator sim(config, file.scene);
    for (int column = 0; column < 3; ++column) {
      const avs::sim::SimFrame frame =
          sim.render(static_cast<std::uint64_t>(frames[column]), t, head);
      const int x0 = frame.image.width / 2 - kCrop / 2, y0 = frame.image.height / 2 - kCrop / 2;
      for (int y = 0; y < kCrop * kZoom; ++y) {
        for (int x = 0; x < kCrop * kZoom; ++x) {
          const int out_x = column * (kCrop * kZoom + 4) + x, out_y = row * (kCrop * kZoom + 4) + y;
          figure.pixels[static_cast<std::size_t>(out_y) * figure.width + out_x] =
              frame.image.at(x0 + x / kZoom, y0 + y / kZoom);
        }
      }
    }
  }
  avs::decode::write_png_gray8(path, figure);
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) {
    std::cerr << "usage: " << argv[0] << " SCENE.yaml OUT_DIR [TIME_S] [PROFILES_PNG]\n";
    return 2;
  }
  try {
    avs::sim::SceneFile file = avs::sim::load_scene(argv[1]);
    const double t = argc > 3 ? std::atof(argv[3]) : 0.0;
    avs::sim::HeadState head;
    if (!file.scene.objects.empty()) {
      head = avs::sim::at_rest(avs::geometry::look_at(
          file.config.head, file.scene.objects[0].trajectory->T_world_object(t).translation()));
    }
    if (argc > 4) {
      write_profiles_png(argv[4], file, t, head);
      std::cout << "wrote " << argv[4] << '\n';
    }
    avs::sim::Simulator sim(file.config, std::move(file.scene));
    const int frames = 2 * sim.config().renderer.geometry.layout.bit_count;
    for (int f = 0; f < frames; ++f) {
      const avs::sim::SimFrame frame = sim.render(static_cast<std::uint64_t>(f), t, head);
      char name[32];
      std::snprintf(name, sizeof(name), "/frame_%02d.pgm", f);
      write_pgm(argv[2] + std::string(name), frame.image.width, frame.image.height,
                frame.image.pixels.data());
    }
    const auto& depth = sim.renderer().depth_m();
    float near = 1e9f, far = 0;
    for (float z : depth) {
      if (z > 0) near = std::min(near, z), far = std::max(far, z);
    }
    std::vector<std::uint8_t> depth8(depth.size(), 0);
    for (std::size_t i = 0; i < depth.size(); ++i) {
      if (depth[i] > 0) {
        depth8[i] =
            static_cast<std::uint8_t>(255 - 200 * (depth[i] - near) / std::max(far - near, 1e-6f));
      }
    }
    write_pgm(argv[2] + std::string("/depth.pgm"), sim.renderer().width(), sim.renderer().height(),
              depth8.data());
    std::cout << "wrote " << frames << " frames and depth.pgm (depth " << near << " .. " << far
              << " m) to " << argv[2] << '\n';
  } catch (const std::exception& e) {
    std::cerr << "avs_sim_snapshot: " << e.what() << '\n';
    return 1;
  }
  return 0;
}
