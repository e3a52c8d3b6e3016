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
#include <sstream>
#include <string>
#include <vector>

#include "avs/bag/file_split.hpp"
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
                                       "0: chunks close by size only"),
                       ParamSpec::real("max_size_mb", 0.0, 0.0, 1e9, "MB",
                                       "start a new file (<stem>_1.mcap, <stem>_2.mcap, ...) "
                                       "when one reaches this size; each file is complete on "
                                       "its own (0: one file)"),
                       ParamSpec::real("max_duration_s", 0.0, 0.0, 1e9, "s",
                                       "start a new file when one covers this much log time "
                                       "(container clock; 0: no limit)")},
        .open_ports = true,
    };
  }

  explicit BagRecorderComponent(runtime::ComponentContext& ctx)
      : Component(ctx),
        file_(file_to_write(ctx.param<std::string>("file"), ctx.param<std::string>("if_exists"))),
        max_chunk_age_ns_(static_cast<std::int64_t>(ctx.param<double>("max_chunk_age_s") * 1e9)),
        split_{static_cast<std::uint64_t>(ctx.param<double>("max_size_mb") * 1e6),
               ctx.param<double>("max_duration_s")},
        if_exists_(ctx.param<std::string>("if_exists")),
        current_file_(file_) {
    if (file_ != ctx.param<std::string>("file")) {
      log().warn("bag_recorder: ", ctx.param<std::string>("file"),
                 " exists and is kept (if_exists: keep); recording into ", file_);
    }
    const std::string topics = ctx.param<std::string>("topics");
    if (topics.empty()) throw runtime::Error("bag_recorder: parameter 'topics' is required");
    const std::string compression = ctx.param<std::string>("compression");
    options_.compression = compression == "lz4"    ? mcap::Compression::lz4
                           : compression == "none" ? mcap::Compression::none
                                                   : mcap::Compression::zstd;
    runtime::QosProfile qos;
    qos.depth = static_cast<std::uint32_t>(ctx.param<int>("depth"));
    for (const std::string& name : msg::parse_name_list(topics, 0, "topics")) {
      Channel& channel = channels_[name];
      channel.topic = name;
      const std::string dds_type = ctx.serialized_subscription(
          name, "", qos, [this, &channel](std::span<const std::byte> cdr) { write(channel, cdr); });
      channel.ros_type = introspection::ros_type_name(dds_type);
      channel.definition =
          introspection::ros2msg_definition(introspection::built_in_types(), dds_type);
      const std::vector<runtime::dds::EndpointQos> offered = {
          runtime::dds::EndpointQos::from_profile(qos)};
      channel.offered_qos = offered_qos_yaml(offered);
    }
    if (split_.enabled()) {
      // The split names are checked now as well: a stale <stem>_1.mcap fails the start, not the
      // recording an hour in (fail), or is said to be overwritten when reached (overwrite).
      std::error_code ec;
      const std::string second = split_path(file_, 1).string();
      if (std::filesystem::exists(second, ec) && if_exists_ == "fail")
        throw runtime::Error("bag_recorder: " + second +
                             " exists (if_exists: fail; the file "
                             "after " +
                             file_ + " when it splits)");
      if (std::filesystem::exists(second, ec) && if_exists_ == "overwrite")
        log().warn(
            "bag_recorder: ", second,
            " (and maybe more <stem>_N.mcap) exist from an "
            "earlier recording: each is overwritten when this one reaches it, the rest stay");
    }
    open_file();
    log().info("recording ", channels_.size(), " topic(s) into ", file_);
    if (split_.enabled()) {
      std::ostringstream when;
      if (split_.max_size_bytes > 0)
        when << "once one reaches " << ctx.param<double>("max_size_mb") << " MB";
      if (split_.max_size_bytes > 0 && split_.max_duration_s > 0) when << " or ";
      if (split_.max_duration_s > 0)
        when << "once one covers " << split_.max_duration_s << " s of log time";
      log().info("a new file (", split_path(file_, 1).filename().string(), ", ...) ", when.str());
    }
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
            {"file", current_file_},
            {"file_index", std::to_string(file_index_)},
            {"error", failure_}};
  }

 private:
  struct Channel {
    std::string topic;
    std::string ros_type;     ///< schema name
    std::string definition;   ///< schema data (ros2msg)
    std::string offered_qos;  ///< channel metadata
    mcap::ChannelId id = 0;   ///< in the open file
  };

  /// Opens file number file_index_ (split_path) with every channel; the first on construction,
  /// the next ones when the split rule starts a new file.
  void open_file() {
    check(writer_.open(current_file_, options_), "open");
    for (auto& [name, channel] : channels_) {
      mcap::SchemaId schema = 0;
      check(writer_.add_schema(channel.ros_type, "ros2msg", channel.definition, schema),
            "add schema " + channel.ros_type);
      check(
          writer_.add_channel(
              name, "cdr", schema,
              {{"offered_qos_profiles", channel.offered_qos}, {"topic_type_hash", ""}}, channel.id),
          "add channel " + name);
    }
    file_start_ns_ = -1;
    std::lock_guard lock(mutex_);
    written_before_file_ = written_;
  }

  /// Closes the open file (complete, with its summary) and continues in the next one. On a
  /// failure the recording stops (write() says so); the messages the closed file lacks are
  /// counted as not written.
  mcap::Status next_file() {
    if (const mcap::Status closed = writer_.close(); !closed.ok()) {
      std::lock_guard lock(mutex_);
      settle_open_file();
      return {closed.code(),
              "close " + current_file_ + " to start the next file: " + closed.to_string()};
    }
    {
      std::lock_guard lock(mutex_);
      settle_open_file();  // complete: nothing to move, but the next file counts from here
    }
    const std::string closed = current_file_;
    // Never over another recording: with if_exists keep a name that exists is skipped.
    namespace fs = std::filesystem;
    int index = file_index_ + 1;
    std::error_code ec;
    for (; if_exists_ != "overwrite" && fs::exists(split_path(file_, index), ec); ++index) {
      if (if_exists_ == "fail" || index >= file_index_ + 100000) {
        return {mcap::StatusCode::io_error, "start the file after " + closed + ": " +
                                                split_path(file_, index).string() +
                                                " exists (if_exists: " + if_exists_ + ")"};
      }
      log().warn("bag_recorder: ", split_path(file_, index).string(),
                 " exists and is kept (if_exists: keep); skipping to the next name");
    }
    {
      std::lock_guard lock(mutex_);
      file_index_ = index;
      current_file_ = split_path(file_, file_index_).string();
    }
    try {
      open_file();
    } catch (const std::exception& e) {
      return {mcap::StatusCode::io_error, std::string("start the next file: ") + e.what()};
    }
    log().info("closed ", closed, ", recording continues in ", current_file_);
    return {};
  }

  /// The open file's messages that did not reach it (a failed write or close loses the chunk
  /// being filled and the queued ones) move from written_ to not_written_; from here on the
  /// open file counts anew. Under mutex_.
  void settle_open_file() {
    const std::uint64_t in_this_file = written_ - written_before_file_;
    const std::uint64_t lost =
        in_this_file - std::min(in_this_file, writer_.statistics().messages_in_file);
    written_ -= lost;
    not_written_ += lost;
    written_before_file_ = written_;
  }

  /// A write the file refuses (disk full, I/O error) ends the recording, loudly, and only the
  /// recording: the rest of the graph goes on (issue 20 section 5). What was written stays
  /// readable up to its last complete chunk (`avs bag info`, `avs bag repair`).
  void write(const Channel& channel, std::span<const std::byte> cdr) {
    if (!failure_.empty()) {
      std::lock_guard lock(mutex_);
      ++not_written_;
      return;
    }
    const auto now = static_cast<mcap::Timestamp>(std::max<std::int64_t>(0, context().now().ns));
    mcap::Status status;
    if (split_.enabled() && file_start_ns_ >= 0 &&
        split_.starts_new_file(writer_.statistics().file_bytes,
                               static_cast<std::uint64_t>(file_start_ns_), now)) {
      status = next_file();
      chunk_start_ns_ = -1;
    }
    const bool split_failed = !status.ok();
    if (file_start_ns_ < 0) file_start_ns_ = static_cast<std::int64_t>(now);
    if (status.ok()) status = writer_.write(channel.id, now, now, cdr);
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
    failure_ =
        split_failed ? status.to_string() : "write " + channel.topic + ": " + status.to_string();
    log().error("bag_recorder: ", current_file_, ": ", failure_, ": recording STOPPED after ",
                written_, " message(s); the rest of the graph goes on",
                split_failed ? ""
                             : "; the file is readable up to its last complete chunk "
                               "(`avs bag repair` gives it a summary)");
  }

  void close() {
    if (closed_) return;  // on_shutdown, then the destructor
    closed_ = true;
    const mcap::Status status = writer_.is_open() ? writer_.close() : mcap::Status::success();
    std::lock_guard lock(mutex_);
    if (!failure_.empty()) {
      // What the files hold: every file before the failure, and the open one's complete chunks;
      // the messages of the chunk being filled then are lost with it.
      settle_open_file();
      log().error("bag_recorder: ", file_, file_index_ > 0 ? " .. " + current_file_ : std::string(),
                  ": ", written_,
                  file_index_ > 0 ? " message(s) in the files, " : " message(s) in the file, ",
                  not_written_, " NOT written (", failure_, ")");
    } else if (!status.ok()) {
      log().error("bag_recorder: ", current_file_, ": close: ", status.to_string(), " (", written_,
                  " message(s) written; `avs bag repair` rebuilds the summary)");
    } else {
      log().info("wrote ", written_, " message(s) to ", file_,
                 file_index_ > 0 ? " .. " + current_file_ : std::string());
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
      throw runtime::Error("bag_recorder: " + current_file_ + ": " + what + ": " +
                           status.to_string());
    }
  }

  const std::string file_;  ///< the first file; split_path names the next ones
  const std::int64_t max_chunk_age_ns_;
  std::int64_t chunk_start_ns_ = -1;  ///< log time of the open chunk's first message; -1: none
  const FileSplit split_;
  const std::string if_exists_;  ///< for the split files too
  mcap::WriterOptions options_;
  int file_index_ = 0;               ///< of the open file (0: file_)
  std::string current_file_;         ///< the open file
  std::int64_t file_start_ns_ = -1;  ///< log time of its first message; -1: none yet
  mcap::Writer writer_;
  std::map<std::string, Channel> channels_;
  mutable std::mutex mutex_;  ///< the counts and failure_ are read by the diagnostics timer
  std::uint64_t written_ = 0;
  std::uint64_t not_written_ = 0;          ///< after a failed write
  std::uint64_t written_before_file_ = 0;  ///< written_ when the open file started
  bool closed_ = false;
  std::string failure_;  ///< the write that failed; empty while recording
};

AVS_REGISTER_COMPONENT(BagRecorderComponent);

}  // namespace
}  // namespace avs::bag
