// Deterministic test content for the MCAP tests: real ros2msg schema text and hand-encoded
// CDR (XCDR1, little endian) for std_msgs/msg/String, geometry_msgs/msg/PointStamped and
// sensor_msgs/msg/Image, written through avs::mcap::Writer.
#pragma once

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include <unistd.h>

#include "avs/mcap/reader.hpp"
#include "avs/mcap/writer.hpp"

namespace avs::mcap::test {

/// A CDR stream: 4-byte encapsulation header (CDR_LE), alignment relative to the body.
class CdrWriter {
 public:
  CdrWriter() { bytes_ = {0x00, 0x01, 0x00, 0x00}; }
  void align(std::size_t n) {
    while ((bytes_.size() - 4) % n != 0) bytes_.push_back(0);
  }
  template <typename T>
  void put(T value) {
    align(sizeof(T));
    unsigned char raw[sizeof(T)];
    std::memcpy(raw, &value, sizeof(T));  // the test machine is little endian (x86-64)
    bytes_.insert(bytes_.end(), raw, raw + sizeof(T));
  }
  void put_string(const std::string& s) {
    put<std::uint32_t>(static_cast<std::uint32_t>(s.size() + 1));
    bytes_.insert(bytes_.end(), s.begin(), s.end());
    bytes_.push_back(0);
  }
  void put_u8_sequence(const std::vector<std::uint8_t>& v) {
    put<std::uint32_t>(static_cast<std::uint32_t>(v.size()));
    bytes_.insert(bytes_.end(), v.begin(), v.end());
  }
  std::vector<std::byte> take() {
    std::vector<std::byte> out(bytes_.size());
    std::memcpy(out.data(), bytes_.data(), bytes_.size());
    return out;
  }

 private:
  std::vector<unsigned char> bytes_;
};

inline const std::string kSeparator = std::string(80, '=') + "\n";
inline const std::string kStringSchema = "string data\n";
inline const std::string kTimeText = "int32 sec\nuint32 nanosec\n";
inline const std::string kHeaderText = "builtin_interfaces/Time stamp\nstring frame_id\n";
inline const std::string kPointStampedSchema =
    "std_msgs/Header header\nPoint point\n\n" + kSeparator + "MSG: builtin_interfaces/Time\n" +
    kTimeText + "\n" + kSeparator +
    "MSG: geometry_msgs/Point\nfloat64 x\nfloat64 y\nfloat64 z\n\n" + kSeparator +
    "MSG: std_msgs/Header\n" + kHeaderText;
inline const std::string kImageSchema =
    "std_msgs/Header header\nuint32 height\nuint32 width\nstring encoding\nuint8 is_bigendian\n"
    "uint32 step\nuint8[] data\n\n" +
    kSeparator + "MSG: builtin_interfaces/Time\n" + kTimeText + "\n" + kSeparator +
    "MSG: std_msgs/Header\n" + kHeaderText;
inline const std::string kQos =
    "- history: 3\n  depth: 0\n  reliability: 1\n  durability: 2\n  deadline:\n    sec: "
    "2147483647\n    nsec: 4294967295\n  lifespan:\n    sec: 2147483647\n    nsec: 4294967295\n"
    "  liveliness: 1\n  liveliness_lease_duration:\n    sec: 2147483647\n    nsec: 4294967295\n"
    "  avoid_ros_namespace_conventions: false\n";

struct TestMessage {
  std::string topic;
  Timestamp log_time = 0;
  Timestamp publish_time = 0;
  std::uint32_t sequence = 0;
  std::vector<std::byte> data;
  // Decoded values, for the independent (JavaScript) check.
  std::string text;            // String.data
  double x = 0, y = 0, z = 0;  // PointStamped.point
  std::uint32_t width = 0, height = 0;
  std::string frame_id;
  std::int32_t sec = 0;
  std::uint32_t nanosec = 0;
};

inline std::vector<std::byte> encode_string(const std::string& s) {
  CdrWriter w;
  w.put_string(s);
  return w.take();
}

inline std::vector<std::byte> encode_point_stamped(std::int32_t sec, std::uint32_t nanosec,
                                                   const std::string& frame, double x, double y,
                                                   double z) {
  CdrWriter w;
  w.put<std::int32_t>(sec);
  w.put<std::uint32_t>(nanosec);
  w.put_string(frame);
  w.put<double>(x);
  w.put<double>(y);
  w.put<double>(z);
  return w.take();
}

inline std::vector<std::uint8_t> image_pixels(std::uint32_t width, std::uint32_t height,
                                              std::uint32_t seed) {
  std::vector<std::uint8_t> pixels(static_cast<std::size_t>(width) * height);
  for (std::size_t i = 0; i < pixels.size(); ++i) {
    pixels[i] = static_cast<std::uint8_t>((i * 7 + seed * 13) & 0xFF);
  }
  return pixels;
}

inline std::vector<std::byte> encode_image(std::int32_t sec, std::uint32_t nanosec,
                                           const std::string& frame, std::uint32_t width,
                                           std::uint32_t height, std::uint32_t seed) {
  CdrWriter w;
  w.put<std::int32_t>(sec);
  w.put<std::uint32_t>(nanosec);
  w.put_string(frame);
  w.put<std::uint32_t>(height);
  w.put<std::uint32_t>(width);
  w.put_string("mono8");
  w.put<std::uint8_t>(0);
  w.put<std::uint32_t>(width);
  w.put_u8_sequence(image_pixels(width, height, seed));
  return w.take();
}

/// The golden content: three topics at 100/50/20 Hz over 0.5 s, log times increasing,
/// publish time 1 ms earlier, images 32x16.
inline std::vector<TestMessage> golden_messages() {
  std::vector<TestMessage> out;
  const Timestamp t0 = 1'700'000'000'000'000'000ull;
  for (int tick = 0; tick < 50; ++tick) {  // 10 ms ticks
    const Timestamp t = t0 + static_cast<Timestamp>(tick) * 10'000'000ull;
    const auto sec = static_cast<std::int32_t>(t / 1'000'000'000ull);
    const auto nanosec = static_cast<std::uint32_t>(t % 1'000'000'000ull);
    TestMessage chatter;
    chatter.topic = "/chatter";
    chatter.log_time = t;
    chatter.publish_time = t - 1'000'000;
    chatter.sequence = static_cast<std::uint32_t>(tick);
    chatter.text = "hello " + std::to_string(tick);
    chatter.data = encode_string(chatter.text);
    out.push_back(chatter);
    if (tick % 2 == 0) {
      TestMessage point;
      point.topic = "/point";
      point.log_time = t + 1000;
      point.publish_time = t;
      point.sec = sec;
      point.nanosec = nanosec;
      point.frame_id = "world";
      point.x = tick * 0.5;
      point.y = -tick * 0.25;
      point.z = 1.0 / (tick + 1);
      point.data = encode_point_stamped(sec, nanosec, point.frame_id, point.x, point.y, point.z);
      out.push_back(point);
    }
    if (tick % 5 == 0) {
      TestMessage image;
      image.topic = "/camera/image";
      image.log_time = t + 2000;
      image.publish_time = t;
      image.sec = sec;
      image.nanosec = nanosec;
      image.frame_id = "camera";
      image.width = 32;
      image.height = 16;
      image.data =
          encode_image(sec, nanosec, image.frame_id, 32, 16, static_cast<std::uint32_t>(tick));
      out.push_back(image);
    }
  }
  return out;
}

/// Writes `messages` with the three golden channels (and a rosbag2 Metadata record).
inline Status write_test_bag(const std::filesystem::path& path, const WriterOptions& options,
                             const std::vector<TestMessage>& messages) {
  Writer writer;
  if (Status s = writer.open(path, options); !s.ok()) return s;
  SchemaId string_schema = 0, point_schema = 0, image_schema = 0;
  if (Status s = writer.add_schema("std_msgs/msg/String", "ros2msg", kStringSchema, string_schema);
      !s.ok()) {
    return s;
  }
  if (Status s = writer.add_schema("geometry_msgs/msg/PointStamped", "ros2msg", kPointStampedSchema,
                                   point_schema);
      !s.ok()) {
    return s;
  }
  if (Status s = writer.add_schema("sensor_msgs/msg/Image", "ros2msg", kImageSchema, image_schema);
      !s.ok()) {
    return s;
  }
  const KeyValueMap metadata{{"offered_qos_profiles", kQos}, {"topic_type_hash", ""}};
  std::map<std::string, ChannelId> channels;
  for (auto [topic, schema] : {std::pair{"/chatter", string_schema},
                               {"/point", point_schema},
                               {"/camera/image", image_schema}}) {
    if (Status s = writer.add_channel(topic, "cdr", schema, metadata, channels[topic]); !s.ok()) {
      return s;
    }
  }
  if (Status s = writer.add_metadata("rosbag2", {{"serialized_metadata", "version: 8\n"}});
      !s.ok()) {
    return s;
  }
  for (const TestMessage& m : messages) {
    if (Status s =
            writer.write(channels.at(m.topic), m.log_time, m.publish_time, m.data, m.sequence);
        !s.ok()) {
      return s;
    }
  }
  return writer.close();
}

inline WriterOptions golden_options(Compression compression) {
  WriterOptions options;
  options.library = "avs-mcap golden";
  options.compression = compression;
  options.chunk_size_bytes = 2048;
  return options;
}

inline std::filesystem::path source_dir() {
  const char* dir = std::getenv("AVS_SOURCE_DIR");
  return dir != nullptr ? std::filesystem::path(dir)
                        : std::filesystem::path(AVS_SOURCE_DIR_DEFAULT);
}

inline std::vector<std::byte> read_bytes(const std::filesystem::path& path) {
  std::vector<std::byte> bytes(std::filesystem::file_size(path));
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (f == nullptr) return {};
  std::size_t n = std::fread(bytes.data(), 1, bytes.size(), f);
  std::fclose(f);
  bytes.resize(n);
  return bytes;
}

struct ReadMessage {
  std::string topic;
  std::string schema_name;
  Timestamp log_time = 0;
  Timestamp publish_time = 0;
  std::uint32_t sequence = 0;
  std::vector<std::byte> data;
};

inline Status read_all(Reader& reader, std::vector<ReadMessage>& out,
                       const ReadOptions& options = {}, ReadReport* report = nullptr) {
  out.clear();
  return reader.read_messages(
      [&](const MessageView& view) {
        out.push_back({view.channel->topic, view.schema ? view.schema->name : "", view.log_time,
                       view.publish_time, view.sequence,
                       std::vector<std::byte>(view.data.begin(), view.data.end())});
        return true;
      },
      options, report);
}

/// The golden content in exactly 9 zstd chunks, with its summary (the bag had 9), and
/// one bit flipped in the compressed records of chunk `corrupt` (none when out of range).
inline std::vector<std::byte> nine_chunk_bag(std::vector<ChunkIndex>& chunks,
                                             std::size_t corrupt = 9) {
  const auto path = std::filesystem::temp_directory_path() /
                    ("avs_mcap_nine_chunks_" + std::to_string(::getpid()) + ".mcap");
  std::vector<std::byte> bytes;
  for (std::uint64_t chunk_size = 1800; chunk_size > 1000; chunk_size -= 20) {
    WriterOptions options = golden_options(Compression::zstd);
    options.chunk_size_bytes = chunk_size;
    chunks.clear();
    if (!write_test_bag(path, options, golden_messages()).ok()) break;
    bytes = read_bytes(path);
    Reader reader;
    if (!reader.open_memory(bytes).ok() || !reader.read_summary().ok()) break;
    chunks = reader.summary().chunk_indexes;
    if (chunks.size() >= 9) break;
  }
  std::filesystem::remove(path);
  if (chunks.size() != 9) return {};  // the caller checks for 9 chunks
  if (corrupt < chunks.size()) {
    const ChunkIndex& c = chunks[corrupt];
    bytes[c.chunk_start_offset + c.chunk_length - c.compressed_size / 2] ^= std::byte{0x08};
  }
  return bytes;
}

/// Messages of the golden content outside `chunk`'s time range (its chunks do not overlap).
inline std::size_t messages_outside(const ChunkIndex& chunk) {
  std::size_t n = 0;
  for (const auto& m : golden_messages()) {
    n += m.log_time < chunk.message_start_time || m.log_time > chunk.message_end_time ? 1 : 0;
  }
  return n;
}

}  // namespace avs::mcap::test
