// Player: republishes the serialised samples of an MCAP file with their original timing
// (log time differences / rate) and each channel's recorded QoS (`avs bag play`).
#pragma once

#include <atomic>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <string>
#include <vector>

namespace avs::bag {

struct PlayOptions {
  std::filesystem::path file;
  double rate = 1.0;  ///< speed factor; 0 < rate
  bool loop = false;
  double start_offset_s = 0;                  ///< skip this much of the bag's start
  std::vector<std::string> topics;            ///< ROS names; empty: every topic
  std::map<std::string, std::string> remaps;  ///< ROS name -> ROS name
  bool clock = false;                         ///< publish rosgraph_msgs/Clock (log time) on /clock
  double clock_period_s = 0.01;  ///< /clock also between messages, at least this often (bag time)
  double delay_s = 0.5;  ///< wait after creating the writers (discovery) before the first sample
  /// Longest wait between two messages, in bag time: a longer gap (a corrupted log_time once
  /// made play wait 73 years) is shortened to this and said.
  double max_gap_s = 10.0;
  int domain = 0;
  std::string partition;  ///< DDS partition of the readers/writers; empty: default
};

struct PlayProgress {
  double bag_time_s = 0;  ///< position in the bag (from its start)
  double duration_s = 0;  ///< bag duration
  std::uint64_t published = 0;
  bool paused = false;
  int pass = 0;  ///< loop pass (0 first)
};

struct PlayControl {
  const std::atomic<bool>* stop = nullptr;               ///< set to stop
  const std::atomic<bool>* paused = nullptr;             ///< while true, time stands still
  std::function<void(const PlayProgress&)> on_progress;  ///< called about every 100 ms
};

struct PlayResult {
  std::uint64_t published = 0;
  std::map<std::string, std::uint64_t> per_topic;  ///< by published (remapped) name
  std::vector<std::string> skipped;                ///< channels not played, with the reason
  std::vector<std::string> skipped_chunks;         ///< corrupt chunks left out, with the reason
  std::uint64_t gaps_shortened = 0;                ///< gaps above max_gap_s (every pass)
};

/// Plays `options.file`; returns when done or stopped. Throws runtime::Error naming the file
/// and offset when it cannot be read (a file without summary: run `avs bag repair`).
PlayResult play(const PlayOptions& options, const PlayControl& control = {});

}  // namespace avs::bag
