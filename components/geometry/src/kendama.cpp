// The built-in ken (see kendama.hpp for the frame and the dimensions).
#include "avs/geometry/kendama.hpp"

#include <cmath>
#include <numbers>
#include <vector>

#include "avs/geometry/primitives.hpp"

namespace avs::geometry {
namespace {

// Lathe meshes are built about +Z; these rotations carry +Z onto the ken's axes.
Eigen::Isometry3d z_to_y() {
  return Eigen::Isometry3d(Eigen::AngleAxisd(-std::numbers::pi / 2, Eigen::Vector3d::UnitX()));
}
Eigen::Isometry3d z_to_x() {
  return Eigen::Isometry3d(Eigen::AngleAxisd(std::numbers::pi / 2, Eigen::Vector3d::UnitY()));
}

/// Handle with the bottom cup, which opens towards -Y. Heights along +Y.
std::vector<ProfilePoint> handle_profile(const KenDimensions& d) {
  const double rim = d.bottom_rim_y_m, cup = d.bottom_cup_radius_m;
  const double inner = cup - 0.002, depth = d.cup_depth_m, neck = d.handle_neck_radius_m;
  const double wide = d.handle_radius_max_m;
  return {
      {0, rim + depth},                    // centre of the dish
      {0.5 * inner, rim + 0.7 * depth},    // dish, falling towards the rim
      {0.85 * inner, rim + 0.25 * depth},  //
      {inner, rim},                        // inner edge of the rim
      {cup, rim},                          // outer edge of the rim
      {cup, rim + 0.003},                  // rim wall
      {0.85 * cup, rim + 0.009},           // cup body curving in
      {0.6 * cup, rim + 0.016},            //
      {neck, rim + 0.022},                 // neck
      {0.5 * (neck + wide), rim + 0.035},  // handle swelling
      {wide, rim + 0.060},                 //
      {wide, rim + 0.080},                 //
      {0.9 * wide, rim + 0.100},           // narrowing under the crosspiece
      {0.84 * wide, -0.006},               // ends inside the crosspiece
      {0, -0.006},
  };
}

/// Crosspiece along its own axis (-> +X): small cup at the - end, big cup at the + end.
std::vector<ProfilePoint> crosspiece_profile(const KenDimensions& d) {
  const double depth = d.cup_depth_m, body = d.crosspiece_radius_m;
  const double s_rim = d.small_cup_rim_x_m, s_cup = d.small_cup_radius_m, s_in = s_cup - 0.002;
  const double b_rim = d.big_cup_rim_x_m, b_cup = d.big_cup_radius_m, b_in = b_cup - 0.0025;
  return {
      {0, s_rim + depth},                   // small cup dish centre
      {0.5 * s_in, s_rim + 0.7 * depth},    //
      {0.85 * s_in, s_rim + 0.25 * depth},  //
      {s_in, s_rim},                        // small cup rim
      {s_cup, s_rim},                       //
      {s_cup, s_rim + 0.0025},              //
      {0.8 * s_cup, s_rim + 0.007},         // flaring into the body
      {0.95 * body, s_rim + 0.012},         //
      {body, -0.012},                       // body
      {body, 0.012},                        //
      {0.95 * body, b_rim - 0.016},         // flaring into the big cup
      {0.7 * b_cup, b_rim - 0.009},         //
      {0.92 * b_cup, b_rim - 0.005},        //
      {b_cup, b_rim - 0.003},               //
      {b_cup, b_rim},                       // big cup rim
      {b_in, b_rim},                        //
      {0.85 * b_in, b_rim - 0.25 * depth},  // dish
      {0.5 * b_in, b_rim - 0.7 * depth},    //
      {0, b_rim - depth},                   // big cup dish centre
  };
}

/// Spike from inside the crosspiece to the tip.
std::vector<ProfilePoint> spike_profile(const KenDimensions& d) {
  const double base = d.spike_base_radius_m, tip = d.spike_tip_y_m;
  return {
      {0, 0.006},
      {base, 0.006},        // starts inside the crosspiece
      {base, 0.017},        // shoulder just above it
      {0.9 * base, 0.022},  //
      {0.65 * base, tip - 0.025},
      {0.38 * base, tip - 0.010},
      {0.16 * base, tip - 0.0025},
      {0, tip},  // tip
  };
}

}  // namespace

Mesh make_ken(const KenDimensions& dimensions) {
  Mesh ken;
  Mesh handle = make_lathe(handle_profile(dimensions), dimensions.segments);
  transform(handle, z_to_y());
  append(ken, handle);
  Mesh crosspiece = make_lathe(crosspiece_profile(dimensions), 2 * dimensions.segments);
  transform(crosspiece, z_to_x());
  append(ken, crosspiece);
  Mesh spike = make_lathe(spike_profile(dimensions), dimensions.segments);
  transform(spike, z_to_y());
  append(ken, spike);
  return ken;
}

}  // namespace avs::geometry
