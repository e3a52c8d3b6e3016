// `avs patterns --out DIR` for a LightCrafter 4500: every 1-bit pattern PNG is the bit plane
// lut.csv names in the flash image lut.csv names (the 24-bit BMPs read back here with a
// reader of their own), in the LUT's order, 24 patterns per image.
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "avs/decode/png_io.hpp"
#include "avs/testing/child_process.hpp"

namespace avs::projector {
namespace {

std::vector<std::vector<std::string>> read_csv(const std::filesystem::path& file) {
  std::ifstream in(file);
  std::vector<std::vector<std::string>> rows;
  for (std::string line; std::getline(in, line);) {
    std::vector<std::string> fields;
    std::stringstream s(line);
    for (std::string f; std::getline(s, f, ',');) fields.push_back(f);
    rows.push_back(fields);
  }
  return rows;
}

/// A 24-bit bottom-up BMP: width, height and the (B, G, R) of a pixel.
struct Bmp {
  std::vector<std::uint8_t> bytes;
  std::uint32_t u32(std::size_t at) const {
    return bytes[at] | bytes[at + 1] << 8 | bytes[at + 2] << 16 |
           static_cast<std::uint32_t>(bytes[at + 3]) << 24;
  }
  int width() const { return static_cast<int>(u32(18)); }
  int height() const { return static_cast<int>(u32(22)); }
  /// Channel byte of pixel (x, y): 0 blue, 1 green, 2 red (the file's order).
  std::uint8_t at(int x, int y, int channel) const {
    const std::size_t row = (static_cast<std::size_t>(width()) * 3 + 3) / 4 * 4;
    return bytes[u32(10) + static_cast<std::size_t>(height() - 1 - y) * row +
                 3 * static_cast<std::size_t>(x) + static_cast<std::size_t>(channel)];
  }
};

Bmp read_bmp(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  return {std::vector<std::uint8_t>(std::istreambuf_iterator<char>(in), {})};
}

TEST(FlashImages, AvsPatternsPacksEveryPatternIntoTheBitPlaneTheLutNames) {
  const auto dir =
      std::filesystem::temp_directory_path() / ("avs_flash_images_" + std::to_string(getpid()));
  std::filesystem::remove_all(dir);
  // 13 bits: 26 patterns, so two flash images (24 + 2).
  const std::string log = dir.string() + ".log";
  const int status = testing::run_program(
      {AVS_EXE, "patterns", "--out", dir.string(), "--bits", "13", "--codes", "40", "--rows", "40",
       "--width", "9", "--height", "44", "--first-flash-image", "2"},
      {}, log);
  ASSERT_EQ(status, 0) << testing::read_file(log);
  std::filesystem::remove(log);

  const auto index = read_csv(dir / "index.csv");
  const auto lut = read_csv(dir / "lut.csv");
  ASSERT_EQ(index.size(), 27u);
  ASSERT_EQ(lut.size(), 27u);
  EXPECT_EQ(lut[0][0], "entry");
  EXPECT_TRUE(std::filesystem::exists(dir / "flash_image_00.bmp"));
  EXPECT_TRUE(std::filesystem::exists(dir / "flash_image_01.bmp"));
  EXPECT_FALSE(std::filesystem::exists(dir / "flash_image_02.bmp"));
  int lit = 0;
  for (std::size_t k = 1; k < lut.size(); ++k) {
    const auto& entry = lut[k];
    EXPECT_EQ(entry[1], index[k][2]) << "bit_index of entry " << k - 1;
    EXPECT_EQ(entry[2], index[k][3]) << "polarity of entry " << k - 1;
    EXPECT_EQ(entry[3], k - 1 < 24 ? "flash_image_00.bmp" : "flash_image_01.bmp");
    EXPECT_EQ(std::stoi(entry[4]), k - 1 < 24 ? 2 : 3);
    const int plane = std::stoi(entry[5]);
    EXPECT_EQ(plane, static_cast<int>((k - 1) % 24));
    EXPECT_EQ(entry[9], plane == 0 ? "1" : "0") << "buffer swap where an image starts";
    // Planes 0-7 green, 8-15 red, 16-23 blue (the controller's 1-bit pattern numbers).
    static constexpr int kFileChannel[] = {1, 2, 0};
    const Bmp bmp = read_bmp(dir / entry[3]);
    const decode::GrayImage8 png = decode::read_png_gray8((dir / index[k][1]).string());
    ASSERT_EQ(bmp.width(), png.width);
    ASSERT_EQ(bmp.height(), png.height);
    for (int y = 0; y < png.height; ++y) {
      for (int x = 0; x < png.width; ++x) {
        const bool in_png = png.pixels[static_cast<std::size_t>(y * png.width + x)] >= 128;
        const bool in_bmp = (bmp.at(x, y, kFileChannel[plane / 8]) >> (plane % 8) & 1) != 0;
        ASSERT_EQ(in_bmp, in_png) << "entry " << k - 1 << " pixel " << x << "," << y;
        lit += in_png ? 1 : 0;
      }
    }
  }
  EXPECT_GT(lit, 0);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace avs::projector
