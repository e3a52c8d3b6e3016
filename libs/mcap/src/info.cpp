#include "avs/mcap/info.hpp"

#include <algorithm>
#include <cstdio>
#include <ctime>

#include "avs/mcap/reader.hpp"

namespace avs::mcap {

Status read_bag_info(const std::filesystem::path& path, BagInfo& info) {
  info = BagInfo{};
  info.path = path;
  Reader reader;
  if (Status s = reader.open(path); !s.ok()) return s;
  info.file_size_bytes = reader.file_size();
  info.profile = reader.header().profile;
  info.library = reader.header().library;
  Summary summary;
  if (reader.read_summary().ok() && reader.summary().statistics) {
    info.from_summary = true;
    summary = reader.summary();
  } else {
    ScanResult scanned;
    if (Status s = reader.scan(scanned, /*allow_truncated=*/true); !s.ok()) {
      return Status(s.code(), path.string() + ": " + s.message());
    }
    info.truncated = scanned.truncated;
    info.truncated_at = scanned.truncated_at;
    summary = std::move(scanned.summary);
  }
  const Statistics stats = summary.statistics.value_or(Statistics{});
  info.start_time = stats.message_start_time;
  info.end_time = stats.message_end_time;
  info.duration_s = static_cast<double>(info.end_time - info.start_time) * 1e-9;
  info.message_count = stats.message_count;
  info.chunk_count = summary.chunk_indexes.size();
  for (const ChunkIndex& chunk : summary.chunk_indexes) {
    ++info.chunks_by_compression[chunk.compression.empty() ? "none" : chunk.compression];
    info.chunk_compressed_bytes += chunk.compressed_size;
    info.chunk_uncompressed_bytes += chunk.uncompressed_size;
  }
  for (const auto& [id, channel] : summary.channels) {
    TopicInfo topic;
    topic.topic = channel.topic;
    topic.message_encoding = channel.message_encoding;
    auto schema = summary.schemas.find(channel.schema_id);
    topic.type = schema == summary.schemas.end() ? "" : schema->second.name;
    auto count = stats.channel_message_counts.find(id);
    topic.message_count = count == stats.channel_message_counts.end() ? 0 : count->second;
    topic.rate_hz =
        info.duration_s > 0 ? static_cast<double>(topic.message_count) / info.duration_s : 0;
    info.topics.push_back(std::move(topic));
  }
  std::sort(info.topics.begin(), info.topics.end(),
            [](const TopicInfo& a, const TopicInfo& b) { return a.topic < b.topic; });
  for (const MetadataIndex& index : summary.metadata_indexes) {
    Metadata m;
    if (Status s = reader.read_metadata(index, m); s.ok()) {
      info.metadata.push_back(std::move(m));
    } else {
      info.metadata_problems.push_back(s.to_string());
    }
  }
  return {};
}

namespace {

std::string format_time(Timestamp t) {
  const std::time_t seconds = static_cast<std::time_t>(t / 1000000000ull);
  std::tm utc{};
  gmtime_r(&seconds, &utc);
  char date[40];
  std::strftime(date, sizeof(date), "%Y-%m-%d %H:%M:%S", &utc);
  char text[96];
  std::snprintf(text, sizeof(text), "%s.%09llu UTC (%llu.%09llu)", date,
                static_cast<unsigned long long>(t % 1000000000ull),
                static_cast<unsigned long long>(t / 1000000000ull),
                static_cast<unsigned long long>(t % 1000000000ull));
  return text;
}

std::string format_bytes(std::uint64_t bytes) {
  const char* units[] = {"B", "KiB", "MiB", "GiB", "TiB"};
  double value = static_cast<double>(bytes);
  int unit = 0;
  while (value >= 1024 && unit < 4) {
    value /= 1024;
    ++unit;
  }
  char text[32];
  std::snprintf(text, sizeof(text), unit == 0 ? "%.0f %s" : "%.2f %s", value, units[unit]);
  return text;
}

}  // namespace

std::string format_bag_info(const BagInfo& info) {
  std::string out;
  char line[512];
  auto add = [&](const char* label, const std::string& value) {
    std::snprintf(line, sizeof(line), "%-13s %s\n", label, value.c_str());
    out += line;
  };
  add("Files:", info.path.string());
  add("Bag size:", format_bytes(info.file_size_bytes));
  add("Storage:", "mcap (profile \"" + info.profile + "\", written by \"" + info.library + "\")");
  std::snprintf(line, sizeof(line), "%.3f s", info.duration_s);
  add("Duration:", line);
  add("Start:", format_time(info.start_time));
  add("End:", format_time(info.end_time));
  add("Messages:", std::to_string(info.message_count));
  std::string compression;
  for (const auto& [name, count] : info.chunks_by_compression) {
    if (!compression.empty()) compression += ", ";
    compression += name + " x" + std::to_string(count);
  }
  if (info.chunk_uncompressed_bytes > 0) {
    std::snprintf(line, sizeof(line), " (%s -> %s, ratio %.2f)",
                  format_bytes(info.chunk_uncompressed_bytes).c_str(),
                  format_bytes(info.chunk_compressed_bytes).c_str(),
                  static_cast<double>(info.chunk_uncompressed_bytes) /
                      static_cast<double>(std::max<std::uint64_t>(info.chunk_compressed_bytes, 1)));
    compression += line;
  }
  add("Chunks:",
      std::to_string(info.chunk_count) + (compression.empty() ? "" : ": " + compression));
  if (!info.from_summary) {
    add("Index:", info.truncated ? "none (file truncated at offset " +
                                       std::to_string(info.truncated_at) + "; run `avs bag repair`)"
                                 : "none (rebuilt by a linear scan)");
  }
  out += "Topics:\n";
  for (const TopicInfo& topic : info.topics) {
    std::snprintf(line, sizeof(line), "  %-32s %-36s count %-10llu %10.2f Hz  %s\n",
                  topic.topic.c_str(), topic.type.c_str(),
                  static_cast<unsigned long long>(topic.message_count), topic.rate_hz,
                  topic.message_encoding.c_str());
    out += line;
  }
  for (const Metadata& m : info.metadata) {
    // The recorder's own record in full (its loss figures); others (rosbag2's YAML) by name.
    if (m.name != "avs_bag_record") {
      out += "Metadata: " + m.name + " (" + std::to_string(m.metadata.size()) + " key(s))\n";
      continue;
    }
    out += "Metadata: " + m.name + " (what the recorder received, lost and reconciled)\n";
    for (const auto& [key, value] : m.metadata) out += "  " + key + ": " + value + "\n";
  }
  for (const std::string& problem : info.metadata_problems)
    out += "Metadata: NOT readable: " + problem + "\n";
  return out;
}

}  // namespace avs::mcap
