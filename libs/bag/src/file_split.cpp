#include "avs/bag/file_split.hpp"

#include <algorithm>
#include <string>

namespace avs::bag {

bool FileSplit::starts_new_file(std::uint64_t file_bytes, std::uint64_t file_start_ns,
                                std::uint64_t log_time_ns) const {
  const bool too_big = max_size_bytes > 0 && file_bytes >= max_size_bytes;
  const bool too_long =
      max_duration_s > 0 &&
      static_cast<double>(log_time_ns - std::min(log_time_ns, file_start_ns)) * 1e-9 >=
          max_duration_s;
  return too_big || too_long;
}

std::filesystem::path split_path(const std::filesystem::path& first, int index) {
  if (index == 0) return first;
  std::filesystem::path p = first;
  const std::string ext = p.has_extension() ? p.extension().string() : std::string(".mcap");
  p.replace_filename(p.stem().string() + "_" + std::to_string(index) + ext);
  return p;
}

}  // namespace avs::bag
