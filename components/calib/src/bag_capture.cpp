#include "avs/calib/bag_capture.hpp"

#include <algorithm>
#include <cstdio>
#include <stdexcept>
#include <vector>

#include "avs/bag/bag_source.hpp"
#include "avs/msg/type_support.hpp"
#include "avs/runtime/dds.hpp"
#include "avs/runtime/raw_topic.hpp"
#include "avs/runtime/time.hpp"

namespace avs::calib {
namespace {

using Image = msgs::sensor_msgs::Image;

/// The images of `topic`, decoded, in log-time order.
class ImageReader {
 public:
  ImageReader(const std::filesystem::path& file, const std::string& topic,
              const runtime::dds::Participant& participant)
      : stream_(file, {topic}) {
    const bag::ReplayChannel& channel = stream_.channels().front();
    const std::string want = msg::TypeSupport<Image>::dds_name;
    if (channel.type->dds_name != want) {
      throw std::runtime_error(file.string() + ": " + topic + " is a " + channel.type->dds_name +
                               ", not " + want);
    }
    codec_.emplace(participant, *channel.type);
  }
  std::shared_ptr<const Image> next() {
    std::optional<bag::StreamedMessage> m = stream_.next();
    if (!m) return nullptr;
    return std::static_pointer_cast<const Image>(codec_->to_sample(m->data));
  }

 private:
  bag::BagStream stream_;
  std::optional<runtime::dds::CdrCodec> codec_;
};

std::int64_t stamp_ns(const Image& image) {
  return runtime::from_ros_time(image.header.stamp).ns;
}

/// The median step between the stamps of the first frames (one exposure per pattern).
std::int64_t recorded_period_ns(const std::filesystem::path& file, const std::string& topic,
                                const runtime::dds::Participant& participant) {
  ImageReader reader(file, topic, participant);
  std::vector<std::int64_t> steps;
  std::optional<std::int64_t> last;
  while (steps.size() < 255) {
    const std::shared_ptr<const Image> image = reader.next();
    if (!image) break;
    const std::int64_t t = stamp_ns(*image);
    if (last && t > *last) steps.push_back(t - *last);
    last = t;
  }
  if (steps.size() < 8) {
    throw std::runtime_error(file.string() + ": too few frames on " + topic +
                             " to tell the pattern period (give --rate)");
  }
  std::nth_element(steps.begin(), steps.begin() + static_cast<std::ptrdiff_t>(steps.size() / 2),
                   steps.end());
  return steps[steps.size() / 2];
}

}  // namespace

BagCaptureStats capture_from_bag(const std::filesystem::path& file, const CaptureCodes& codes,
                                 const BagCaptureConfig& config,
                                 const std::function<void(BoardView&&)>& on_view,
                                 const std::function<void(const std::string&)>& log) {
  // Cyclone's serialiser of the type needs a participant (nothing is sent through it).
  const runtime::dds::Participant participant(static_cast<dds_domainid_t>(config.dds_domain));
  const std::int64_t period_ns = config.rate_hz > 0
                                     ? static_cast<std::int64_t>(1e9 / config.rate_hz + 0.5)
                                     : recorded_period_ns(file, config.topic, participant);
  BagCaptureStats stats;
  stats.period_ms = static_cast<double>(period_ns) / 1e6;
  log("pattern period " + std::to_string(stats.period_ms) + " ms" +
      (config.rate_hz > 0 ? " (--rate)" : " (from the recording's stamps)"));

  ImageReader reader(file, config.topic, participant);
  StampedFrameIds ids(period_ns);
  AssemblerConfig assembler_config = config.assembler;
  assembler_config.frame_id_bits = 64;  // ids from stamps: no wrap, no skipped 0
  assembler_config.frame_id_zero_skipped = false;
  std::optional<ViewAssembler> assembler;
  std::vector<decode::GrayImage8> taken_whites;
  RepeatedReasons reasons(log);
  const auto note = [&](const std::string& reason) {
    reasons.add("message " + std::to_string(stats.messages) + ": " + reason);
  };
  while (const std::shared_ptr<const Image> image = reader.next()) {
    ++stats.messages;
    const auto width = static_cast<int>(image->width);
    const auto height = static_cast<int>(image->height);
    const std::string encoding(image->encoding ? image->encoding : "");
    if (!assembler && encoding == "mono8" && width > 0 && height > 0) {
      stats.width = width;
      stats.height = height;
      assembler.emplace(codes, width, height, assembler_config);
    }
    if (encoding != "mono8" || width != stats.width || height != stats.height ||
        image->step < image->width ||
        image->data._length < static_cast<std::uint64_t>(image->step) * image->height) {
      ++stats.bad_images;
      note("a " + std::to_string(width) + " x " + std::to_string(height) + " '" + encoding +
           "' image with " + std::to_string(image->data._length) + " bytes; expected mono8 " +
           std::to_string(stats.width) + " x " + std::to_string(stats.height) + ": not used");
      continue;
    }
    std::string why;
    const std::optional<std::uint64_t> id = ids.id(stamp_ns(*image), why);
    if (!id) {
      ++stats.off_grid;
      note(why);
      continue;
    }
    AssemblerResult result = assembler->push(
        *id, {image->data._buffer, width, height, static_cast<std::ptrdiff_t>(image->step)});
    if (!result.rejected.empty()) {
      ++stats.rejected_cycles;
      note(result.rejected);
    }
    if (!result.view) continue;
    if (!is_new_pose(*result.view, taken_whites, assembler_config.moved_threshold_dn,
                     config.min_new_pose_fraction)) {
      ++stats.same_pose;
      continue;
    }
    reasons.flush();
    ++stats.views;
    taken_whites.push_back(result.view->frames[0]);
    on_view(std::move(*result.view));
  }
  reasons.flush();
  return stats;
}

}  // namespace avs::calib
