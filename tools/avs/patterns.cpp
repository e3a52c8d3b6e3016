// avs patterns --out DIR: writes the Gray-code projector patterns (Eq. 1, section 4.1) as 8-bit
// PNG files in projection order (bit 0 = MSB positive, bit 0 negative, bit 1 positive, ...),
// named so that they sort in that order, plus index.csv saying which file is which bit and
// polarity, ready to load into a projector's pattern sequence. For a DLP LightCrafter 4500
// (the `projector` component) it also writes what its flash needs: flash_image_NN.bmp, 24-bit
// images packing 24 1-bit patterns each in the order the pattern LUT uses, and lut.csv, the
// LUT the component sends (docs/devices.md section 7).
#include <filesystem>
#include <fstream>
#include <iostream>

#include "commands.hpp"
#include "flash_images.hpp"

#if __has_include("avs/decode/png_io.hpp")
#include "avs/decode/calibration_yaml.hpp"
#include "avs/decode/patterns.hpp"
#include "avs/decode/png_io.hpp"
#define AVS_HAVE_DECODE 1
#endif
#if __has_include("avs/projector/pattern_sequence.hpp")
#include "avs/projector/pattern_sequence.hpp"
#define AVS_HAVE_PROJECTOR 1
#endif

namespace avs::cli {

namespace {

struct PatternsOptions {
  std::string out;
  std::string calibration;
  int bits = 9;
  int codes = 265;
  int rows = 1060;
  int first_row = -1;
  int width = 912;
  int height = 1140;
  int first_flash_image = 0;
};

#ifdef AVS_HAVE_DECODE
int write_patterns(const PatternsOptions& o, Command& cmd) {
  // Projector size and layout: the calibration's, unless given on the command line.
  decode::CodeLayout layout;
  int width = o.width;
  int height = o.height;
  int rows = o.rows;
  if (!o.calibration.empty()) {
    const decode::SensorGeometry g = decode::load_sensor_geometry_yaml(o.calibration);
    layout = g.layout;
    if (cmd.count("--width") == 0) width = g.projector.width;
    if (cmd.count("--height") == 0) height = g.projector.height;
    if (cmd.count("--rows") == 0) rows = layout.used_rows();
  }
  if (o.calibration.empty() || cmd.count("--bits") > 0) layout.bit_count = o.bits;
  if (o.calibration.empty() || cmd.count("--codes") > 0) layout.code_count = o.codes;
  if (layout.code_count <= 0 || rows <= 0 || rows % layout.code_count != 0) {
    std::cerr << "avs patterns: --rows " << rows << " is not a positive multiple of --codes "
              << layout.code_count << " (each code covers the same number of rows)\n";
    return 2;
  }
  layout.rows_per_code = rows / layout.code_count;
  if (o.first_row >= 0) {
    layout.first_row = o.first_row;
  } else if (o.calibration.empty() || cmd.count("--rows") > 0 || cmd.count("--height") > 0) {
    layout.first_row = (height - rows) / 2;  // centred
  }
  if (layout.bit_count < 1 || layout.bit_count > 15 ||
      layout.code_count > (1 << layout.bit_count)) {
    std::cerr << "avs patterns: " << layout.code_count << " codes do not fit " << layout.bit_count
              << " bits (at most 2^bits, bits in 1..15)\n";
    return 2;
  }
  if (layout.first_row < 0 || layout.first_row + rows > height) {
    std::cerr << "avs patterns: rows " << layout.first_row << ".." << layout.first_row + rows - 1
              << " do not fit a projector of " << height << " rows\n";
    return 2;
  }

  const std::filesystem::path dir(o.out);
  std::filesystem::create_directories(dir);
  const auto patterns = decode::make_patterns(layout, width, height);
  std::ofstream index(dir / "index.csv");
  index << "index,file,bit_index,polarity,bit_count,code_count,rows_per_code,first_row,width,"
           "height\n";
  int n = 0;
  for (const decode::PatternImage& p : patterns) {
    const bool positive = p.polarity == decode::Polarity::kPositive;
    char name[64];
    std::snprintf(name, sizeof name, "pattern_%02d_bit%02d_%s.png", n, p.bit_index,
                  positive ? "pos" : "neg");
    decode::write_png_gray8((dir / name).string(), {p.width, p.height, p.pixels});
    index << n << ',' << name << ',' << p.bit_index << ',' << (positive ? "positive" : "negative")
          << ',' << layout.bit_count << ',' << layout.code_count << ',' << layout.rows_per_code
          << ',' << layout.first_row << ',' << width << ',' << height << '\n';
    ++n;
  }
  index.close();
  if (!index) {
    std::cerr << "avs patterns: cannot write " << (dir / "index.csv").string() << '\n';
    return 1;
  }
  std::cout << "wrote " << n << " patterns (" << width << "x" << height << ", " << layout.bit_count
            << " bits, " << layout.code_count << " codes x " << layout.rows_per_code
            << " rows from row " << layout.first_row << ") and index.csv to " << dir.string()
            << '\n';
#ifdef AVS_HAVE_PROJECTOR
  std::vector<std::vector<std::uint8_t>> pixels;
  std::vector<std::string> labels;
  for (const decode::PatternImage& p : patterns) {
    pixels.push_back(p.pixels);
    labels.push_back(std::to_string(p.bit_index) +
                     (p.polarity == decode::Polarity::kPositive ? ",positive" : ",negative"));
  }
  if (write_flash_images(pixels, labels, "bit_index,polarity", width, height, o.first_flash_image,
                         dir) < 0) {
    std::cerr << "avs patterns: cannot write the flash images or lut.csv to " << dir.string()
              << '\n';
    return 1;
  }
  const int images = (n + projector::kPatternsPerImage - 1) / projector::kPatternsPerImage;
  std::cout << "wrote " << images << " LightCrafter 4500 flash image(s) "
            << "(flash_image_NN.bmp, 24 1-bit patterns each) and lut.csv (its pattern LUT, "
               "first flash image index "
            << o.first_flash_image << ")\n";
#endif
  return 0;
}
#endif

void add_patterns_command(Command& app) {
  auto* cmd = app.add_subcommand(
      "patterns",
      "Write the Gray-code projector patterns (Eq. 1) as PNG files in projection order "
      "(bit 0 positive, bit 0 negative, ...) with index.csv, and the LightCrafter 4500's flash "
      "images (24 patterns per 24-bit BMP) with lut.csv");
  static PatternsOptions o;
  cmd->add_option("--out", o.out, "output folder (created)")->required();
  cmd->add_option("--calibration", o.calibration,
                  "sensor geometry YAML: projector size and code layout from it");
  cmd->add_option("--bits", o.bits, "n, code bits (MSB = bit 0)")
      ->capture_default_str()
      ->check_range(1, 15);
  cmd->add_option("--codes", o.codes, "codes used (at most 2^bits)")
      ->capture_default_str()
      ->check_range(2, 32768);
  cmd->add_option("--rows", o.rows, "projector rows carrying codes (a multiple of --codes)")
      ->capture_default_str()
      ->check_range(1, 16384);
  cmd->add_option("--first-row", o.first_row,
                  "projector row where code 0 starts (default: coded rows centred)")
      ->check_range(0, 16383);
  cmd->add_option("--width", o.width, "projector width, pixels")
      ->capture_default_str()
      ->check_range(1, 16384);
  cmd->add_option("--height", o.height, "projector height, pixels")
      ->capture_default_str()
      ->check_range(1, 16384);
  cmd->add_option("--first-flash-image", o.first_flash_image,
                  "LightCrafter 4500: flash image index where flash_image_00.bmp is stored "
                  "(the projector component's first_flash_image)")
      ->capture_default_str()
      ->check_range(0, 255);
  cmd->callback([cmd] {
#ifdef AVS_HAVE_DECODE
    try {
      exit_status() = write_patterns(o, *cmd);
    } catch (const std::exception& e) {
      std::cerr << "avs patterns: " << e.what() << '\n';
      exit_status() = 1;
    }
#else
    (void)cmd;
    std::cerr << "avs patterns: this avs was built without components/decode (AVS_ONLY_SUBDIRS)\n";
    exit_status() = 1;
#endif
  });
}

}  // namespace

AVS_REGISTER_COMMAND(add_patterns_command)

}  // namespace avs::cli
