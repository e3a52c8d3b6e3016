#include "avs/matching/voxel_grid.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace avs::matching {
namespace {

constexpr int kKeyBits = 21;
constexpr std::int64_t kKeyOffset = std::int64_t{1} << (kKeyBits - 1);
constexpr std::int64_t kKeyMask = (std::int64_t{1} << kKeyBits) - 1;

std::uint64_t voxel_key(const Eigen::Vector3f& p, float inverse_size) {
  std::uint64_t key = 0;
  for (int axis = 0; axis < 3; ++axis) {
    const auto cell = static_cast<std::int64_t>(std::floor(p[axis] * inverse_size)) + kKeyOffset;
    key =
        (key << kKeyBits) | static_cast<std::uint64_t>(std::clamp<std::int64_t>(cell, 0, kKeyMask));
  }
  return key;
}

}  // namespace

void voxel_downsample(const Points& in, float voxel_size_m, Points& out, VoxelGridScratch& scratch,
                      const Points* normals_in, Points* normals_out) {
  if (!(voxel_size_m > 0.0F)) {
    throw std::invalid_argument("voxel_downsample: voxel_size_m must be > 0, got " +
                                std::to_string(voxel_size_m));
  }
  if (normals_in != nullptr && normals_in->size() != in.size()) {
    throw std::invalid_argument("voxel_downsample: normals_in has " +
                                std::to_string(normals_in->size()) + " entries for " +
                                std::to_string(in.size()) + " points");
  }
  const float inverse_size = 1.0F / voxel_size_m;
  auto& keyed = scratch.keyed;
  keyed.resize(in.size());
  for (std::size_t i = 0; i < in.size(); ++i) {
    keyed[i] = {voxel_key(in[i], inverse_size), static_cast<std::uint32_t>(i)};
  }
  std::sort(keyed.begin(), keyed.end());
  out.clear();
  if (normals_out != nullptr) normals_out->clear();
  for (std::size_t begin = 0; begin < keyed.size();) {
    std::size_t end = begin;
    Eigen::Vector3f sum = Eigen::Vector3f::Zero();
    Eigen::Vector3f normal_sum = Eigen::Vector3f::Zero();
    while (end < keyed.size() && keyed[end].first == keyed[begin].first) {
      sum += in[keyed[end].second];
      if (normals_in != nullptr) normal_sum += (*normals_in)[keyed[end].second];
      ++end;
    }
    out.push_back(sum / static_cast<float>(end - begin));
    if (normals_out != nullptr) {
      const float norm = normal_sum.norm();
      normals_out->push_back(norm > 1e-6F ? Eigen::Vector3f(normal_sum / norm)
                                          : Eigen::Vector3f::Zero());
    }
    begin = end;
  }
}

Points voxel_downsample(const Points& in, float voxel_size_m) {
  Points out;
  VoxelGridScratch scratch;
  voxel_downsample(in, voxel_size_m, out, scratch);
  return out;
}

}  // namespace avs::matching
