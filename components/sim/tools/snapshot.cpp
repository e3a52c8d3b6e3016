// avs_sim_snapshot SCENE.yaml OUT_DIR [TIME_S]
// Renders the 2n pattern frames of one cycle at TIME_S (default 0) with the head aimed at
// the first object, and writes OUT_DIR/frame_XX.pgm plus OUT_DIR/depth.pgm (near = bright).
#include <algorithm>
#include <cstdlib>
#include <exception>
#include <fstream>
#include <iostream>
#include <string>

#include "avs/sim/scene_yaml.hpp"
#include "avs/sim/simulator.hpp"

namespace {

void write_pgm(const std::string& path, int width, int height, const std::uint8_t* pixels) {
  std::ofstream out(path, std::ios::binary);
  out << "P5\n" << width << ' ' << height << "\n255\n";
  out.write(reinterpret_cast<const char*>(pixels), static_cast<std::streamsize>(width) * height);
  if (!out) throw std::runtime_error(path + ": write failed");
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) {
    std::cerr << "usage: " << argv[0] << " SCENE.yaml OUT_DIR [TIME_S]\n";
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
