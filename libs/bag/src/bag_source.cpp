#include "avs/bag/bag_source.hpp"

#include <cstdio>
#include <map>

#include "avs/bag/qos_yaml.hpp"
#include "avs/bag/replay_schedule.hpp"
#include "avs/introspection/type_database.hpp"
#include "avs/runtime/error.hpp"
#include "avs/runtime/topic_name.hpp"

namespace avs::bag {

using runtime::Error;

std::string ros_topic_name(const std::string& name) {
  if (name.rfind("rt/", 0) == 0) return runtime::from_dds_topic_name(name);
  return runtime::resolve_topic_name("/", name);
}

ChannelSelection select_channels(const mcap::Summary& summary,
                                 const std::set<std::string>& wanted) {
  ChannelSelection out;
  for (const auto& [id, channel] : summary.channels) {
    if (!wanted.empty() && wanted.count(channel.topic) == 0) continue;
    auto skip = [&](const std::string& why) { out.skipped.push_back(channel.topic + ": " + why); };
    if (channel.message_encoding != "cdr") {
      skip("message encoding '" + channel.message_encoding + "' (only cdr is played)");
      continue;
    }
    auto schema = summary.schemas.find(channel.schema_id);
    if (schema == summary.schemas.end()) {
      skip("no schema (id " + std::to_string(channel.schema_id) + ")");
      continue;
    }
    const msg::TypeEntry* type = msg::find_type(introspection::dds_type_name(schema->second.name));
    if (type == nullptr) {
      skip("type " + schema->second.name + " is not known to this build");
      continue;
    }
    ReplayChannel c;
    c.id = id;
    c.topic = channel.topic;
    c.type = type;
    c.has_header = starts_with_header(schema->second.data);
    auto qos = channel.metadata.find("offered_qos_profiles");
    try {
      if (qos != channel.metadata.end()) c.offered = parse_offered_qos_yaml(qos->second);
    } catch (const std::exception& e) {
      skip(e.what());
      continue;
    }
    out.channels.push_back(std::move(c));
  }
  return out;
}

OpenedBag open_bag(mcap::Reader& reader, const std::filesystem::path& file, const char* who) {
  mcap::ReaderOptions options;
  options.skip_corrupt_chunks = true;  // one bad chunk does not end a replay
  if (mcap::Status s = reader.open(file, options); !s.ok()) {
    throw Error(std::string(who) + ": " + file.string() + ": " + s.to_string());
  }
  OpenedBag out;
  if (mcap::Status s = reader.read_summary(); !s.ok()) {
    mcap::ScanResult scan;
    if (mcap::Status s2 = reader.scan(scan, true); !s2.ok()) {
      throw Error(std::string(who) + ": " + file.string() + ": " + s2.to_string());
    }
    out.scanned = true;
    out.truncated = scan.truncated;
    out.skipped_chunks = scan.skipped_chunks;
    std::fprintf(
        stderr,
        "%s: %s has no usable summary (%s); playing what a scan finds%s "
        "(`avs bag repair` fixes the file)\n",
        who, file.string().c_str(), s.to_string().c_str(),
        scan.truncated ? (", up to offset " + std::to_string(scan.truncated_at)).c_str() : "");
  }
  return out;
}

namespace {

std::string describe(const mcap::SkippedChunk& chunk) {
  return "offset " + std::to_string(chunk.offset) + ": " + chunk.problem;
}

}  // namespace

BagStream::BagStream(const std::filesystem::path& file, const std::vector<std::string>& topics,
                     std::size_t max_queued_bytes)
    : file_(file), max_queued_bytes_(max_queued_bytes) {
  opened_ = open_bag(reader_, file, "bag_player");
  for (const auto& chunk : opened_.skipped_chunks) skipped_chunks_.push_back(describe(chunk));
  std::set<std::string> wanted;
  for (const auto& t : topics) wanted.insert(ros_topic_name(t));
  selection_ = select_channels(reader_.summary(), wanted);
  if (selection_.channels.empty()) {
    std::string why;
    for (const auto& s : selection_.skipped) why += "; " + s;
    throw Error("bag_player: " + file.string() + ": no topic to play" +
                (topics.empty() ? std::string() : " among the ones asked for") + why);
  }
  thread_ = std::thread([this] { read_all(); });
}

BagStream::~BagStream() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  changed_.notify_all();
  thread_.join();
}

std::vector<std::string> BagStream::skipped_chunks() const {
  std::lock_guard lock(mutex_);
  return skipped_chunks_;
}

void BagStream::read_all() {
  std::map<mcap::ChannelId, std::size_t> index;
  mcap::ReadOptions ro;
  for (std::size_t i = 0; i < selection_.channels.size(); ++i) {
    index[selection_.channels[i].id] = i;
    ro.topics.insert(selection_.channels[i].topic);
  }
  ro.allow_truncated = opened_.truncated;
  mcap::ReadReport report;
  std::string error;
  try {
    const mcap::Status s = reader_.read_messages(
        [&](const mcap::MessageView& m) {
          auto it = index.find(m.channel->id);
          if (it == index.end()) return true;
          std::unique_lock lock(mutex_);
          changed_.wait(lock, [&] {
            return stopping_ || queue_.empty() || queued_bytes_ + m.data.size() <= max_queued_bytes_;
          });
          if (stopping_) return false;
          queue_.push_back({it->second, m.log_time, {m.data.begin(), m.data.end()}});
          queued_bytes_ += m.data.size();
          changed_.notify_all();
          return true;
        },
        ro, &report);
    if (!s.ok()) error = "bag_player: " + file_.string() + ": " + s.to_string();
  } catch (const std::exception& e) {
    error = std::string("bag_player: ") + file_.string() + ": " + e.what();
  }
  std::lock_guard lock(mutex_);
  if (report.used_summary) {
    for (const auto& chunk : report.skipped_chunks) skipped_chunks_.push_back(describe(chunk));
  }
  error_ = error;
  done_ = true;
  changed_.notify_all();
}

std::optional<StreamedMessage> BagStream::next() {
  std::unique_lock lock(mutex_);
  changed_.wait(lock, [&] { return done_ || !queue_.empty(); });
  if (queue_.empty()) {
    if (!error_.empty()) throw Error(error_);
    return std::nullopt;
  }
  StreamedMessage m = std::move(queue_.front());
  queue_.pop_front();
  queued_bytes_ -= m.data.size();
  changed_.notify_all();
  return m;
}

}  // namespace avs::bag
