// Splitting a recording into files (`avs bag record --max-size/--max-duration` and the
// bag_recorder component's max_size_mb/max_duration_s), as rosbag2's --max-bag-size and
// --max-bag-duration do: each file complete on its own, named <stem>_1.mcap, <stem>_2.mcap, ...
// after the first. A recorder meant to run for days splits, because an MCAP writer keeps one
// chunk-index entry per chunk until the file is closed (docs/reliability.md, soak).
#pragma once

#include <cstdint>
#include <filesystem>

namespace avs::bag {

struct FileSplit {
  std::uint64_t max_size_bytes = 0;  ///< 0: no size limit
  double max_duration_s = 0;         ///< of log time; 0: no duration limit

  /// Whether either limit is set (else one file).
  [[nodiscard]] bool enabled() const { return max_size_bytes > 0 || max_duration_s > 0; }

  /// Whether the message at log_time_ns starts a new file: the open file (file_bytes written,
  /// its first message at file_start_ns) reached the size or would cover the duration.
  [[nodiscard]] bool starts_new_file(std::uint64_t file_bytes, std::uint64_t file_start_ns,
                                     std::uint64_t log_time_ns) const;
};

/// The name of file `index` of a split recording: `first` itself for 0, else <stem>_<index>
/// with first's extension (.mcap when it has none).
[[nodiscard]] std::filesystem::path split_path(const std::filesystem::path& first, int index);

}  // namespace avs::bag
