// `avs patterns --out DIR`: the PNG files read back are the patterns of Eq. 1 in projection
// order (bit 0 positive, bit 0 negative, ...), the negative inverts the positive on coded rows,
// every projector row decodes to its code, and neighbouring codes differ in exactly one bit.
#include <unistd.h>

#include <bit>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "avs/decode/gray_code.hpp"
#include "avs/decode/png_io.hpp"
#include "avs/testing/child_process.hpp"

namespace avs::decode {
namespace {

struct IndexRow {
  int index = 0;
  std::string file;
  int bit_index = 0;
  std::string polarity;
};

std::vector<IndexRow> read_index(const std::filesystem::path& file) {
  std::ifstream in(file);
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line.rfind("index,file,bit_index,polarity,", 0), 0u) << line;
  std::vector<IndexRow> rows;
  while (std::getline(in, line)) {
    std::stringstream s(line);
    IndexRow r;
    std::string field;
    std::getline(s, field, ',');
    r.index = std::stoi(field);
    std::getline(s, r.file, ',');
    std::getline(s, field, ',');
    r.bit_index = std::stoi(field);
    std::getline(s, r.polarity, ',');
    rows.push_back(r);
  }
  return rows;
}

class PatternsCommand : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ =
        std::filesystem::temp_directory_path() / ("avs_patterns_test_" + std::to_string(getpid()));
    std::filesystem::remove_all(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  int run(std::vector<std::string> options) {
    std::vector<std::string> argv = {AVS_EXE, "patterns", "--out", dir_.string()};
    argv.insert(argv.end(), options.begin(), options.end());
    const std::string log = dir_.string() + ".log";
    const int status = avs::testing::run_program(std::move(argv), {}, log);
    log_ = avs::testing::read_file(log);
    std::filesystem::remove(log);
    return status;
  }

  std::filesystem::path dir_;
  std::string log_;
};

TEST_F(PatternsCommand, WritesEq1PatternsInProjectionOrder) {
  ASSERT_EQ(run({}), 0) << log_;
  const CodeLayout layout{9, 265, 4, 40};  // paper: 265 codes over 1060 of 1140 rows, centred
  const std::vector<IndexRow> index = read_index(dir_ / "index.csv");
  ASSERT_EQ(index.size(), 18u);
  std::vector<std::string> sorted_files;
  for (const auto& e : std::filesystem::directory_iterator(dir_)) {
    if (e.path().extension() == ".png") sorted_files.push_back(e.path().filename().string());
  }
  std::sort(sorted_files.begin(), sorted_files.end());
  ASSERT_EQ(sorted_files.size(), 18u);

  std::vector<GrayImage8> positive(9), negative(9);
  for (std::size_t i = 0; i < index.size(); ++i) {
    const IndexRow& r = index[i];
    EXPECT_EQ(r.index, static_cast<int>(i));
    EXPECT_EQ(r.file, sorted_files[i]) << "file names sort in projection order";
    EXPECT_EQ(r.bit_index, static_cast<int>(i / 2));
    EXPECT_EQ(r.polarity, i % 2 == 0 ? "positive" : "negative");
    GrayImage8 image = read_png_gray8((dir_ / r.file).string());
    ASSERT_EQ(image.width, 912);
    ASSERT_EQ(image.height, 1140);
    (i % 2 == 0 ? positive : negative)[i / 2] = std::move(image);
  }

  // Per projector row: every column equal, 0 or 255; negative = inverted positive on coded
  // rows, both dark outside; the positive bits form the row's Gray code (Eq. 1).
  std::vector<int> code_of(1140, -1);
  for (int row = 0; row < 1140; ++row) {
    const int expected_code = code_of_row(layout, row);
    std::uint32_t gray = 0;
    for (int k = 0; k < 9; ++k) {
      const auto* p = positive[k].pixels.data() + static_cast<std::size_t>(row) * 912;
      const auto* n = negative[k].pixels.data() + static_cast<std::size_t>(row) * 912;
      for (int x = 1; x < 912; ++x) {
        ASSERT_EQ(p[x], p[0]) << "row " << row << " bit " << k;
        ASSERT_EQ(n[x], n[0]) << "row " << row << " bit " << k;
      }
      ASSERT_TRUE(p[0] == 0 || p[0] == 255);
      if (expected_code < 0) {
        ASSERT_EQ(p[0], 0) << "uncoded row " << row;
        ASSERT_EQ(n[0], 0) << "uncoded row " << row;
        continue;
      }
      ASSERT_EQ(n[0], 255 - p[0]) << "row " << row << " bit " << k << ": polarity inversion";
      gray = (gray << 1) | (p[0] == 255 ? 1u : 0u);
    }
    if (expected_code < 0) continue;
    code_of[static_cast<std::size_t>(row)] = static_cast<int>(gray_to_binary(gray));
    ASSERT_EQ(code_of[static_cast<std::size_t>(row)], expected_code) << "row " << row;
  }
  // Neighbouring codes along the rows differ in exactly one pattern bit.
  int transitions = 0;
  for (int row = 41; row < 1140; ++row) {
    const int a = code_of[static_cast<std::size_t>(row - 1)];
    const int b = code_of[static_cast<std::size_t>(row)];
    if (a < 0 || b < 0 || a == b) continue;
    ASSERT_EQ(b, a + 1);
    ASSERT_EQ(std::popcount(binary_to_gray(static_cast<std::uint32_t>(a)) ^
                            binary_to_gray(static_cast<std::uint32_t>(b))),
              1)
        << "codes " << a << " and " << b;
    ++transitions;
  }
  EXPECT_EQ(transitions, 264);
}

TEST_F(PatternsCommand, OptionsChangeLayoutAndBadOnesAreRefused) {
  ASSERT_EQ(
      run({"--bits", "4", "--codes", "16", "--rows", "64", "--width", "32", "--height", "80"}), 0)
      << log_;
  const auto index = read_index(dir_ / "index.csv");
  ASSERT_EQ(index.size(), 8u);
  const GrayImage8 msb = read_png_gray8((dir_ / index[0].file).string());
  ASSERT_EQ(msb.width, 32);
  ASSERT_EQ(msb.height, 80);
  // 16 codes x 4 rows centred in 80 rows: rows 8..71; the MSB of the Gray code is 1 for codes
  // 8..15, i.e. rows 40..71.
  EXPECT_EQ(msb.pixels[7 * 32], 0);
  EXPECT_EQ(msb.pixels[39 * 32], 0);
  EXPECT_EQ(msb.pixels[40 * 32], 255);
  EXPECT_EQ(msb.pixels[71 * 32], 255);
  EXPECT_EQ(msb.pixels[72 * 32], 0);

  EXPECT_NE(run({"--rows", "1000"}), 0);  // not a multiple of 265
  EXPECT_NE(log_.find("multiple"), std::string::npos) << log_;
  EXPECT_NE(run({"--bits", "8"}), 0);  // 265 codes do not fit 8 bits
  EXPECT_NE(log_.find("do not fit"), std::string::npos) << log_;
}

}  // namespace
}  // namespace avs::decode
