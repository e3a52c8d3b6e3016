#include "avs/decode/png_io.hpp"

#include <png.h>

#include <cstdio>
#include <memory>
#include <stdexcept>

namespace avs::decode {
namespace {

struct FileCloser {
  void operator()(std::FILE* f) const { std::fclose(f); }
};
using File = std::unique_ptr<std::FILE, FileCloser>;

[[noreturn]] void on_png_error(png_structp png, png_const_charp message) {
  const auto* path = static_cast<const std::string*>(png_get_error_ptr(png));
  throw std::runtime_error((path ? *path : std::string("<png>")) + ": libpng: " + message);
}

void on_png_warning(png_structp, png_const_charp) {}

}  // namespace

void write_png_gray8(const std::string& path, const GrayImage8& image) {
  if (image.width <= 0 || image.height <= 0 ||
      image.pixels.size() != static_cast<std::size_t>(image.width) * image.height) {
    throw std::invalid_argument(path + ": image of " + std::to_string(image.width) + "x" +
                                std::to_string(image.height) + " with " +
                                std::to_string(image.pixels.size()) + " pixels");
  }
  File file(std::fopen(path.c_str(), "wb"));
  if (!file) throw std::runtime_error(path + ": cannot open for writing");
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, const_cast<std::string*>(&path),
                                            on_png_error, on_png_warning);
  if (png == nullptr) throw std::runtime_error(path + ": png_create_write_struct failed");
  png_infop info = png_create_info_struct(png);
  struct Guard {
    png_structp* png;
    png_infop* info;
    ~Guard() { png_destroy_write_struct(png, info); }
  } guard{&png, &info};
  if (info == nullptr) throw std::runtime_error(path + ": png_create_info_struct failed");
  png_init_io(png, file.get());
  png_set_IHDR(png, info, static_cast<png_uint_32>(image.width),
               static_cast<png_uint_32>(image.height), 8, PNG_COLOR_TYPE_GRAY, PNG_INTERLACE_NONE,
               PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_write_info(png, info);
  for (int y = 0; y < image.height; ++y) {
    png_write_row(png, image.pixels.data() + static_cast<std::size_t>(y) * image.width);
  }
  png_write_end(png, nullptr);
  if (std::fflush(file.get()) != 0) throw std::runtime_error(path + ": write failed");
}

GrayImage8 read_png_gray8(const std::string& path) {
  File file(std::fopen(path.c_str(), "rb"));
  if (!file) throw std::runtime_error(path + ": cannot open for reading");
  png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, const_cast<std::string*>(&path),
                                           on_png_error, on_png_warning);
  if (png == nullptr) throw std::runtime_error(path + ": png_create_read_struct failed");
  png_infop info = png_create_info_struct(png);
  struct Guard {
    png_structp* png;
    png_infop* info;
    ~Guard() { png_destroy_read_struct(png, info, nullptr); }
  } guard{&png, &info};
  if (info == nullptr) throw std::runtime_error(path + ": png_create_info_struct failed");
  png_init_io(png, file.get());
  png_read_info(png, info);
  if (png_get_color_type(png, info) != PNG_COLOR_TYPE_GRAY || png_get_bit_depth(png, info) != 8 ||
      png_get_interlace_type(png, info) != PNG_INTERLACE_NONE) {
    throw std::runtime_error(path + ": expected an 8-bit grayscale, non-interlaced PNG");
  }
  GrayImage8 image;
  image.width = static_cast<int>(png_get_image_width(png, info));
  image.height = static_cast<int>(png_get_image_height(png, info));
  image.pixels.resize(static_cast<std::size_t>(image.width) * image.height);
  for (int y = 0; y < image.height; ++y) {
    png_read_row(png, image.pixels.data() + static_cast<std::size_t>(y) * image.width, nullptr);
  }
  png_read_end(png, nullptr);
  return image;
}

}  // namespace avs::decode
