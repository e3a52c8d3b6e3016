// Writes the golden content with avs::mcap in every compression plus expected.json (the
// values published) for the independent JavaScript reader check (js/check_mcap.mjs).
// usage: mcap_js_fixture OUTPUT_DIR
#include <cstdio>
#include <string>

#include "test_bag.hpp"

namespace {

using avs::mcap::test::TestMessage;

std::string json_string(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') out += '\\';
    out += c;
  }
  return out + "\"";
}

std::string number(double v) {
  char text[40];
  std::snprintf(text, sizeof(text), "%.17g", v);
  return text;
}

std::string header_json(const TestMessage& m) {
  return "{\"stamp\":{\"sec\":" + std::to_string(m.sec) +
         ",\"nanosec\":" + std::to_string(m.nanosec) + "},\"frame_id\":" + json_string(m.frame_id) +
         "}";
}

std::string value_json(const TestMessage& m, std::string& type) {
  if (m.topic == "/chatter") {
    type = "std_msgs/msg/String";
    return "{\"data\":" + json_string(m.text) + "}";
  }
  if (m.topic == "/point") {
    type = "geometry_msgs/msg/PointStamped";
    return "{\"header\":" + header_json(m) + ",\"point\":{\"x\":" + number(m.x) +
           ",\"y\":" + number(m.y) + ",\"z\":" + number(m.z) + "}}";
  }
  type = "sensor_msgs/msg/Image";
  std::string pixels;
  // The seed is the tick: publish_time is the tick's time, 10 ms per tick from t0.
  const auto tick =
      static_cast<std::uint32_t>((m.publish_time - 1'700'000'000'000'000'000ull) / 10'000'000ull);
  for (std::uint8_t p : avs::mcap::test::image_pixels(m.width, m.height, tick)) {
    if (!pixels.empty()) pixels += ",";
    pixels += std::to_string(p);
  }
  return "{\"header\":" + header_json(m) + ",\"height\":" + std::to_string(m.height) +
         ",\"width\":" + std::to_string(m.width) +
         ",\"encoding\":\"mono8\",\"is_bigendian\":0,\"step\":" + std::to_string(m.width) +
         ",\"data\":[" + pixels + "]}";
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s OUTPUT_DIR\n", argv[0]);
    return 2;
  }
  const std::filesystem::path dir = argv[1];
  const auto messages = avs::mcap::test::golden_messages();
  for (auto [name, compression] : {std::pair{"avs_none.mcap", avs::mcap::Compression::none},
                                   {"avs_lz4.mcap", avs::mcap::Compression::lz4},
                                   {"avs_zstd.mcap", avs::mcap::Compression::zstd}}) {
    avs::mcap::Status s = avs::mcap::test::write_test_bag(
        dir / name, avs::mcap::test::golden_options(compression), messages);
    if (!s.ok()) {
      std::fprintf(stderr, "writing %s: %s\n", name, s.to_string().c_str());
      return 1;
    }
  }
  std::string json = "{\"messages\":[\n";
  for (std::size_t i = 0; i < messages.size(); ++i) {
    const TestMessage& m = messages[i];
    std::string type;
    const std::string value = value_json(m, type);
    json += "{\"topic\":" + json_string(m.topic) + ",\"type\":" + json_string(type) +
            ",\"log_time\":\"" + std::to_string(m.log_time) + "\",\"publish_time\":\"" +
            std::to_string(m.publish_time) + "\",\"sequence\":" + std::to_string(m.sequence) +
            ",\"value\":" + value + "}" + (i + 1 < messages.size() ? ",\n" : "\n");
  }
  json += "]}\n";
  std::FILE* f = std::fopen((dir / "expected.json").c_str(), "w");
  if (f == nullptr || std::fwrite(json.data(), 1, json.size(), f) != json.size()) {
    std::fprintf(stderr, "cannot write expected.json in %s\n", dir.c_str());
    return 1;
  }
  std::fclose(f);
  return 0;
}
