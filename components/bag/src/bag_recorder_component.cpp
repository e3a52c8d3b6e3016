// bag_recorder: records topics into an MCAP file from inside a graph (docs/bag.md, "Replay
// inside a graph"). It gets what the container's components publish as they publish it, so
// nothing is lost to a loaded machine: in lockstep the graph waits for it like for any other
// component. Log and publish times are the container's clock (sim time in a simulated graph),
// so two runs of a lockstep graph write the same messages at the same times.
#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <map>
#include <mutex>
#include <string>
#include <vector>

#include "avs/bag/qos_yaml.hpp"
#include "avs/introspection/type_database.hpp"
#include "avs/mcap/writer.hpp"
#include "avs/msg/convert.hpp"
#include "avs/runtime/component.hpp"
#include "avs/runtime/raw_topic.hpp"

namespace avs::bag {
namespace {

using runtime::ParamSpec;

class BagRecorderComponent final : public runtime::Component {
 public:
  static runtime::ComponentSpec spec() {
    return {
        .type = "bag_recorder",
        .description =
            "records topics of the graph into an MCAP file (ros2 profile) on the "
            "container's clock, losing nothing",
        .parameters = {ParamSpec::string("file", "", "the MCAP file to write (required)"),
                       ParamSpec::string("topics", "",
                                         "comma-separated topics (ROS names) to record "
                                         "(required); each has the type the graph's "
                                         "publishers of it declare"),
                       ParamSpec::string("compression", "zstd", "chunk compression",
                                         {"zstd", "lz4", "none"}),
                       ParamSpec::integer("depth", 1000, 1, 1e6, "",
                                          "history depth of the readers of samples from other "
                                          "processes"),
                       ParamSpec::string("if_exists", "keep",
                                         "when the file exists: keep it and record into the "
                                         "next free <stem>.<N>.mcap (a restarted recorder "
                                         "loses nothing), overwrite it, or fail",
                                         {"keep", "overwrite", "fail"}),
                       ParamSpec::real("max_chunk_age_s", 1.0, 0.0, 3600.0, "s",
                                       "a chunk is written once its first message is this old "
                                       "(container clock): what a killed recorder can lose; "
                                       "0: chunks close by size only")},
        .open_ports = true,
    };
  }

  explicit BagRecorderComponent(runtime::ComponentContext& ctx)
      : Component(ctx),
        file_(file_to_write(ctx.param<std::string>("file"), ctx.param<std::string>("if_exists"))),
        max_chunk_age_ns_(static_cast<std::int64_t>(ctx.param<double>("max_chunk_age_s") * 1e9)) {
    if (file_ != ctx.param<std::string>("file")) {
      log().warn("bag_recorder: ", ctx.param<std::string>("file"),
                 " exists and is kept (if_exists: keep); recording into ", file_);
    }
    const std::string topics = ctx.param<std::string>("topics");
    if (topics.empty()) throw runtime::Error("bag_recorder: parameter 'topics' is required");
    mcap::WriterOptions options;
    const std::string compression = ctx.param<std::string>("compression");
    options.compression = compression == "lz4"    ? mcap::Compression::lz4
                          : compression == "none" ? mcap::Compression::none
                                                  : mcap::Compression::zstd;
    check(writer_.open(file_, options), "open");
    runtime::QosProfile qos;
    qos.depth = static_cast<std::uint32_t>(ctx.param<int>("depth"));
    for (const std::string& name : msg::parse_name_list(topics, 0, "topics")) {
      Channel& channel = channels_[name];
      channel.topic = name;
      const std::string dds_type = ctx.serialized_subscription(
          name, "", qos, [this, &channel](std::span<const std::byte> cdr) { write(channel, cdr); });
      const std::string ros_type = introspection::ros_type_name(dds_type);
      mcap::SchemaId schema = 0;
      check(writer_.add_schema(
                ros_type, "ros2msg",
                introspection::ros2msg_definition(introspection::built_in_types(), dds_type),
                schema),
            "add schema " + ros_type);
      const std::vector<runtime::dds::EndpointQos> offered = {
          runtime::dds::EndpointQos::from_profile(qos)};
      check(writer_.add_channel(name, "cdr", schema,
                                {{"offered_qos_profiles", offered_qos_yaml(offered)},
                                 {"topic_type_hash", ""}},
                                channel.id),
            "add channel " + name);
    }
    log().info("recording ", channels_.size(), " topic(s) into ", file_);
  }

  void on_shutdown() override { close(); }
  ~BagRecorderComponent() override {
    try {
      close();
    } catch (const std::exception& e) {
      log().error(e.what());
    }
  }

  std::vector<std::pair<std::string, std::string>> diagnostic_values() const override {
    std::lock_guard lock(mutex_);
    return {{"written", std::to_string(written_)},
            {"not_written", std::to_string(not_written_)},
            {"file", file_},
            {"error", failure_}};
  }

 private:
  struct Channel {
    std::string topic;
    mcap::ChannelId id = 0;
  };

  /// A write the file refuses (disk full, I/O error) ends the recording, loudly, and only the
  /// recording: the rest of the graph goes on (issue 20 section 5). What was written stays
  /// readable up to its last complete chunk (`avs bag info`, `avs bag repair`).
  void write(const Channel& channel, std::span<const std::byte> cdr) {
    if (!failure_.empty()) {
      std::lock_guard lock(mutex_);
      ++not_written_;
      return;
    }
    const auto now =
        static_cast<mcap::Timestamp>(std::max<std::int64_t>(0, context().now().ns));
    mcap::Status status = writer_.write(channel.id, now, now, cdr);
    if (status.ok() && max_chunk_age_ns_ > 0) {
      // Bounds what a SIGKILL can take: only the chunk being filled is lost with the process.
      if (chunk_start_ns_ < 0) {
        chunk_start_ns_ = static_cast<std::int64_t>(now);
      } else if (static_cast<std::int64_t>(now) - chunk_start_ns_ >= max_chunk_age_ns_) {
        status = writer_.flush_chunk();
        chunk_start_ns_ = -1;
      }
    }
    std::lock_guard lock(mutex_);
    if (status.ok()) {
      ++written_;
      return;
    }
    ++not_written_;
    failure_ = "write " + channel.topic + ": " + status.to_string();
    log().error("bag_recorder: ", file_, ": ", failure_, ": recording STOPPED after ", written_,
                " message(s); the rest of the graph goes on; the file is readable up to its last "
                "complete chunk (`avs bag repair` gives it a summary)");
  }

  void close() {
    if (!writer_.is_open()) return;
    const mcap::Status status = writer_.close();
    std::lock_guard lock(mutex_);
    if (!failure_.empty()) {
      // What the file holds: the chunks written before the failure; the messages of the
      // chunk being filled then are lost with it.
      const std::uint64_t in_file = writer_.statistics().messages_in_file;
      log().error("bag_recorder: ", file_, ": ", in_file, " message(s) in the file, ",
                  not_written_ + written_ - std::min(written_, in_file), " NOT written (", failure_,
                  ")");
    } else if (!status.ok()) {
      log().error("bag_recorder: ", file_, ": close: ", status.to_string(), " (", written_,
                  " message(s) written; `avs bag repair` rebuilds the summary)");
    } else {
      log().info("wrote ", written_, " message(s) to ", file_);
    }
  }

  /// The file to record into: `file`, or with if_exists "keep" and `file` present the first
  /// free <stem>.<N><extension> (N from 1), so a respawned recorder keeps the killed run's file.
  static std::string file_to_write(const std::string& file, const std::string& if_exists) {
    if (file.empty()) throw runtime::Error("bag_recorder: parameter 'file' is required");
    namespace fs = std::filesystem;
    const fs::path path(file);
    std::error_code ec;
    if (if_exists == "overwrite" || !fs::exists(path, ec)) return file;
    if (if_exists == "fail") {
      throw runtime::Error("bag_recorder: " + file + " exists (if_exists: fail)");
    }
    for (int n = 1; n < 100000; ++n) {
      fs::path next = path;
      next.replace_filename(path.stem().string() + "." + std::to_string(n) +
                            path.extension().string());
      if (!fs::exists(next, ec)) return next.string();
    }
    throw runtime::Error("bag_recorder: " + file + ": no free name <stem>.<N>" +
                         path.extension().string() + " up to N = 99999");
  }

  /// A write the file refused is a failure of the run (a recording must not lose silently).
  void check(const mcap::Status& status, const std::string& what) const {
    if (!status.ok()) {
      throw runtime::Error("bag_recorder: " + file_ + ": " + what + ": " + status.to_string());
    }
  }

  const std::string file_;
  const std::int64_t max_chunk_age_ns_;
  std::int64_t chunk_start_ns_ = -1;  ///< log time of the open chunk's first message; -1: none
  mcap::Writer writer_;
  std::map<std::string, Channel> channels_;
  mutable std::mutex mutex_;  ///< the counts and failure_ are read by the diagnostics timer
  std::uint64_t written_ = 0;
  std::uint64_t not_written_ = 0;  ///< after a failed write
  std::string failure_;            ///< the write that failed; empty while recording
};

AVS_REGISTER_COMPONENT(BagRecorderComponent);

}  // namespace
}  // namespace avs::bag
