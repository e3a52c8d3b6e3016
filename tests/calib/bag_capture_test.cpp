// Issue 14, section 2: a recording of the rig's camera as a calibration capture source
// (`avs calib capture --source bag`). The test writes what a calibration session recorded by
// launch_config/calib_record.yaml holds: /camera/image_raw (sensor_msgs/Image, mono8, CDR through
// Cyclone's own serialiser, the schema as the recorder writes it) at 1000 patterns/s, the
// projector looping the calibration sequence, the board in each of 8 poses for a few cycles and
// moved between them without a pause in the stream, a pose shown twice, a stamp off the period
// grid, an rgb8 image. Every new pose must come out once, byte for byte the rendered view.
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <regex>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <unistd.h>

#include "avs/bag/qos_yaml.hpp"
#include "avs/calib/bag_capture.hpp"
#include "avs/calib/capture_folder.hpp"
#include "avs/introspection/type_database.hpp"
#include "avs/mcap/writer.hpp"
#include "avs/msg/type_support.hpp"
#include "avs/runtime/dds.hpp"
#include "avs/runtime/raw_topic.hpp"
#include "avs/runtime/time.hpp"
#include "avs/testing/child_process.hpp"
#include "avs/testing/test_domain.hpp"
#include "rendered_views.hpp"

namespace avs::calib {
namespace {

using test::kViews;
using test::projected_frame_of;
using test::rendered;

constexpr std::int64_t kPeriodNs = 1000000;  // 1000 patterns per second

/// /camera/image_raw of a calibration session in an MCAP file, as the recorder writes it.
class SessionBag {
 public:
  explicit SessionBag(const std::filesystem::path& path)
      : participant_(static_cast<dds_domainid_t>(testing::test_domain())),
        codec_(participant_, *msg::find_type(msg::TypeSupport<Image>::dds_name)) {
    EXPECT_TRUE(writer_.open(path).ok());
    const std::string dds_name = msg::TypeSupport<Image>::dds_name;
    mcap::SchemaId schema = 0;
    EXPECT_TRUE(writer_
                    .add_schema(introspection::ros_type_name(dds_name), "ros2msg",
                                introspection::ros2msg_definition(introspection::built_in_types(),
                                                                  dds_name),
                                schema)
                    .ok());
    EXPECT_TRUE(writer_
                    .add_channel("/camera/image_raw", "cdr", schema,
                                 {{"offered_qos_profiles",
                                   bag::offered_qos_yaml({runtime::dds::EndpointQos{}})}},
                                 channel_)
                    .ok());
  }
  void add(std::int64_t stamp_ns, const decode::GrayImage8& image, const char* encoding = "mono8") {
    Image m{};
    runtime::to_ros_time(runtime::Time{stamp_ns}, m.header.stamp);
    m.header.frame_id = const_cast<char*>("camera_optical");
    m.height = static_cast<std::uint32_t>(image.height);
    m.width = static_cast<std::uint32_t>(image.width);
    m.encoding = const_cast<char*>(encoding);
    m.step = static_cast<std::uint32_t>(image.width);
    m.data._buffer = const_cast<std::uint8_t*>(image.pixels.data());
    m.data._length = static_cast<std::uint32_t>(image.pixels.size());
    m.data._maximum = m.data._length;
    const std::vector<std::byte> cdr = codec_.to_cdr(&m);
    const auto t = static_cast<mcap::Timestamp>(stamp_ns);
    EXPECT_TRUE(writer_.write(channel_, t, t, cdr, sequence_++).ok());
  }
  void close() { EXPECT_TRUE(writer_.close().ok()); }

 private:
  using Image = msgs::sensor_msgs::Image;
  runtime::dds::Participant participant_;
  runtime::dds::CdrCodec codec_;
  mcap::Writer writer_;
  mcap::ChannelId channel_ = 0;
  std::uint32_t sequence_ = 0;
};

/// The session: the projector loops from frame 7 of a cycle; each pose for 3 cycles and a bit,
/// the pose after it starting wherever the sequence is (the board moved while it ran); pose 0
/// again at the end (taken once), a frame off the grid, an rgb8 image and a restart of the
/// sequence half a period later on the way.
std::filesystem::path write_session(const std::filesystem::path& dir) {
  const test::Rendered& r = rendered();
  const std::vector<std::size_t> frame_of = projected_frame_of(r.views[0]);
  const std::filesystem::path file = dir / "session.mcap";
  SessionBag bag(file);
  std::int64_t k = 0;         // pattern counter of the projector
  std::int64_t shift_ns = 0;  // the projector restarted later: a new period grid
  const auto show = [&](const BoardView& view, std::int64_t frames) {
    for (std::int64_t i = 0; i < frames; ++i, ++k) {
      bag.add(5'000'000'000 + k * kPeriodNs + shift_ns,
              view.frames[frame_of[(k + 7) % frame_of.size()]]);
    }
  };
  for (int v = 0; v < kViews; ++v) {
    show(r.views[static_cast<std::size_t>(v)], 3 * static_cast<std::int64_t>(frame_of.size()) + 11);
    if (v == 2) {
      bag.add(5'000'000'000 + k * kPeriodNs - kPeriodNs / 2, r.views[2].frames[0]);  // off the grid
    }
    if (v == 5) shift_ns = kPeriodNs / 2;  // from pose 6 on, half a period later
    if (v == 4) {
      const decode::GrayImage8 colour{r.views[4].frames[0].width / 3, r.views[4].frames[0].height,
                                      r.views[4].frames[0].pixels};
      bag.add(5'000'000'000 + k * kPeriodNs, colour, "rgb8");
      ++k;
    }
  }
  show(r.views[0], 3 * static_cast<std::int64_t>(frame_of.size()));  // pose 0 again
  bag.close();
  return file;
}

void expect_views_equal(const std::vector<BoardView>& got) {
  const test::Rendered& r = rendered();
  ASSERT_EQ(static_cast<int>(got.size()), kViews);
  for (int v = 0; v < kViews; ++v) {
    const BoardView& want = r.views[static_cast<std::size_t>(v)];
    ASSERT_EQ(got[static_cast<std::size_t>(v)].frames.size(), want.frames.size());
    for (std::size_t f = 0; f < want.frames.size(); ++f) {
      EXPECT_EQ(got[static_cast<std::size_t>(v)].frames[f].pixels, want.frames[f].pixels)
          << "view " << v << " frame " << f;
    }
  }
}

struct TempDir {
  TempDir()
      : path(std::filesystem::temp_directory_path() /
             ("avs_calib_bag_" + std::to_string(getpid()))) {
    std::filesystem::remove_all(path);
    std::filesystem::create_directories(path);
  }
  ~TempDir() { std::filesystem::remove_all(path); }
  std::filesystem::path path;
};

TEST(CalibBagCapture, EveryNewStillPoseOfARecordedSessionIsOneViewByteForByte) {
  const TempDir dir;
  const std::filesystem::path file = write_session(dir.path);
  BagCaptureConfig config;
  config.dds_domain = testing::test_domain();
  std::vector<BoardView> views;
  std::vector<std::string> log;
  const BagCaptureStats stats = capture_from_bag(
      file, rendered().info.codes, config, [&](BoardView&& v) { views.push_back(std::move(v)); },
      [&](const std::string& line) { log.push_back(line); });
  for (const std::string& line : log) std::printf("%s\n", line.c_str());
  expect_views_equal(views);
  EXPECT_EQ(stats.views, kViews);
  EXPECT_DOUBLE_EQ(stats.period_ms, 1.0);  // from the stamps
  // The stray frame (left out; the frames after it continue the run), and the first two of the
  // new grid (then it is taken).
  EXPECT_EQ(stats.off_grid, 3);
  EXPECT_EQ(stats.bad_images, 1);
  EXPECT_GE(stats.same_pose, 1);  // pose 0 again, and the later cycles of every pose
  EXPECT_EQ(stats.width, 512);
}

TEST(CalibBagCapture, AMissingTopicIsRefusedNamingTheFile) {
  const TempDir dir;
  const std::filesystem::path file = write_session(dir.path);
  BagCaptureConfig config;
  config.dds_domain = testing::test_domain();
  config.topic = "/camera/pattern";
  try {
    capture_from_bag(
        file, rendered().info.codes, config, [](BoardView&&) {}, [](const std::string&) {});
    FAIL() << "read a bag without the topic";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("session.mcap"), std::string::npos) << e.what();
  }
}

#ifdef AVS_PROGRAM
TEST(CalibBagCapture, TheCommandWritesTheCaptureFolderOfARecordedSession) {
  const TempDir dir;
  const std::filesystem::path file = write_session(dir.path);
  const int status = testing::run_program(
      {AVS_PROGRAM, "calib", "capture", "--source", "bag", "--bag", file.string(), "--out",
       (dir.path / "capture").string()},
      {"AVS_DOMAIN_ID=" + std::to_string(testing::test_domain())}, dir.path / "capture.log");
  const std::string out = testing::read_file(dir.path / "capture.log");
  EXPECT_EQ(status, 0) << out;
  EXPECT_NE(out.find("board found in " + std::to_string(kViews)), std::string::npos) << out;
  const CaptureIndex index = read_capture_index(dir.path / "capture");
  EXPECT_EQ(index.info.source, "bag");
  std::vector<BoardView> views;
  for (const ViewEntry& e : index.views) {
    views.push_back(read_view(dir.path / "capture", e, index.info));
  }
  expect_views_equal(views);
  // Without --bag: a one-line reason and exit status 2.
  EXPECT_EQ(testing::run_program({AVS_PROGRAM, "calib", "capture", "--source", "bag", "--out",
                                  (dir.path / "none").string()},
                                 {}, dir.path / "none.log"),
            2);
  EXPECT_NE(testing::read_file(dir.path / "none.log").find("--bag FILE"), std::string::npos);
}

/// The recording graph loops the sequence `avs calib patterns` writes (one count in two places,
/// held together here) from the flash index it writes for, and validates.
TEST(CalibBagCapture, TheRecordingGraphLoopsTheSequenceThatAvsCalibPatternsWrites) {
  const TempDir dir;
  ASSERT_EQ(testing::run_program(
                {AVS_PROGRAM, "calib", "patterns", "--out", (dir.path / "patterns").string()}, {},
                dir.path / "patterns.log"),
            0);
  const std::string written = testing::read_file(dir.path / "patterns.log");
  std::smatch m;
  ASSERT_TRUE(std::regex_search(written, m, std::regex("sequence: (\\d+) patterns"))) << written;
  const std::size_t count = std::stoul(m[1]);
  EXPECT_EQ(count, projection_sequence(calibration_codes(912, 1140, 4)).size());
  EXPECT_NE(written.find("first flash image index 1"), std::string::npos) << written;
  const std::filesystem::path graph =
      std::filesystem::path(AVS_SOURCE_DIR) / "launch_config" / "calib_record.yaml";
  const std::string yaml = testing::read_file(graph);
  ASSERT_TRUE(std::regex_search(yaml, m, std::regex("pattern_count: \\{default: (\\d+)")));
  EXPECT_EQ(std::stoul(m[1]), count);
  ASSERT_TRUE(
      std::regex_search(yaml, m, std::regex("calibration_first_flash_image: \\{default: (\\d+)")));
  EXPECT_EQ(m[1], "1");
  EXPECT_EQ(
      testing::run_program({AVS_PROGRAM, "check", graph.string()}, {}, dir.path / "check.log"), 0)
      << testing::read_file(dir.path / "check.log");
}
#endif  // AVS_PROGRAM

}  // namespace
}  // namespace avs::calib
