// Reading a bag for replay, shared by `avs bag play` (over DDS) and the bag_player component
// (inside a graph): opening it (summary, or a scan when it has none), choosing the channels
// that can be replayed, and a stream of their messages in log-time order read ahead on a
// thread of its own.
#pragma once

#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <filesystem>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "avs/mcap/reader.hpp"
#include "avs/msg/type_registry.hpp"
#include "avs/runtime/raw_topic.hpp"

namespace avs::bag {

/// The ROS name of a topic as given by a user ("chatter", "/chatter" or "rt/chatter").
std::string ros_topic_name(const std::string& name);

/// A channel of a bag that can be replayed: CDR, with a schema of a type this build knows.
struct ReplayChannel {
  mcap::ChannelId id = 0;
  std::string topic;  ///< ROS name
  const msg::TypeEntry* type = nullptr;
  bool has_header = false;  ///< the type begins with std_msgs/Header (replay_schedule.hpp)
  std::vector<runtime::dds::EndpointQos> offered;  ///< as recorded (offered_qos_profiles)
};

struct ChannelSelection {
  std::vector<ReplayChannel> channels;
  std::vector<std::string> skipped;  ///< "topic: why" for each wanted channel not replayable
};

/// The channels of `summary` on `wanted` topics (ROS names; empty: every topic) that can be
/// replayed, and why the others cannot.
ChannelSelection select_channels(const mcap::Summary& summary, const std::set<std::string>& wanted);

/// What opening a bag for replay found.
struct OpenedBag {
  bool scanned = false;    ///< no usable summary: rebuilt by a scan (said on stderr)
  bool truncated = false;  ///< the scan ended at an incomplete tail
  std::vector<mcap::SkippedChunk> skipped_chunks;  ///< corrupt chunks the scan left out
};

/// Opens `file` in `reader` with corrupt chunks skipped, and reads its summary or, when it has
/// none, scans it (said on stderr, prefixed with `who`). Throws runtime::Error naming the file
/// when it cannot be read.
OpenedBag open_bag(mcap::Reader& reader, const std::filesystem::path& file, const char* who);

/// One message read ahead.
struct StreamedMessage {
  std::size_t channel = 0;  ///< index into BagStream::channels()
  mcap::Timestamp log_time = 0;
  std::vector<std::byte> data;
};

/// The messages of the chosen channels of a bag, in log-time order, read on a thread of its
/// own into a queue of at most `max_queued_bytes` (one message more when a single message is
/// larger), so that a consumer never waits for the disk unless it outruns it.
class BagStream {
 public:
  /// Throws runtime::Error naming the file when it cannot be read or has no replayable
  /// channel among `topics` (ROS names; empty: every topic).
  BagStream(const std::filesystem::path& file, const std::vector<std::string>& topics,
            std::size_t max_queued_bytes = 64u << 20);
  ~BagStream();
  BagStream(const BagStream&) = delete;
  BagStream& operator=(const BagStream&) = delete;

  const std::vector<ReplayChannel>& channels() const { return selection_.channels; }
  /// Wanted channels that are not replayed, with the reason.
  const std::vector<std::string>& skipped_channels() const { return selection_.skipped; }
  /// Corrupt chunks left out so far ("offset N: why").
  std::vector<std::string> skipped_chunks() const;

  /// The next message; nullopt at the end. Blocks while the reading thread is behind. Throws
  /// runtime::Error when reading failed (the messages before the failure have been given).
  std::optional<StreamedMessage> next();

 private:
  void read_all();

  std::filesystem::path file_;
  mcap::Reader reader_;
  OpenedBag opened_;
  ChannelSelection selection_;
  std::size_t max_queued_bytes_;
  mutable std::mutex mutex_;
  std::condition_variable changed_;
  std::deque<StreamedMessage> queue_;
  std::size_t queued_bytes_ = 0;
  bool done_ = false;
  bool stopping_ = false;
  std::string error_;
  std::vector<std::string> skipped_chunks_;
  std::thread thread_;
};

}  // namespace avs::bag
