// What `avs bag info FILE` prints: computed from the summary when present, else from a scan.
#pragma once

#include <cstdint>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "avs/mcap/records.hpp"
#include "avs/mcap/status.hpp"

namespace avs::mcap {

struct TopicInfo {
  std::string topic;
  std::string type;  ///< schema name, e.g. "sensor_msgs/msg/Image"
  std::string message_encoding;
  std::uint64_t message_count = 0;
  double rate_hz = 0;  ///< message_count / bag duration (0 when the duration is 0)
};

struct BagInfo {
  std::filesystem::path path;
  std::uint64_t file_size_bytes = 0;
  std::string profile;
  std::string library;
  Timestamp start_time = 0;
  Timestamp end_time = 0;
  double duration_s = 0;
  std::uint64_t message_count = 0;
  std::uint64_t chunk_count = 0;
  std::map<std::string, std::uint64_t> chunks_by_compression;  ///< "none"/"lz4"/"zstd" -> n
  std::uint64_t chunk_compressed_bytes = 0;
  std::uint64_t chunk_uncompressed_bytes = 0;
  std::vector<TopicInfo> topics;  ///< sorted by topic
  bool from_summary = false;      ///< false: rebuilt by a linear scan
  bool truncated = false;         ///< scan stopped at an incomplete tail (repair advised)
  std::uint64_t truncated_at = 0;
  /// The Metadata records (e.g. "rosbag2", and "avs_bag_record": what `avs bag record`
  /// received, lost and reconciled per topic, docs/bag.md "Loss accounting").
  std::vector<Metadata> metadata;
  /// Metadata records that could not be read (the reason each).
  std::vector<std::string> metadata_problems;
};

Status read_bag_info(const std::filesystem::path& path, BagInfo& info);
/// Multi-line, human-readable text.
std::string format_bag_info(const BagInfo& info);

}  // namespace avs::mcap
