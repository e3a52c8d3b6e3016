// The LightCrafter 4500's flash images for a list of 1-bit patterns, and the pattern LUT the
// `projector` component (or `avs calib capture --source camera`) sends for them: shared by
// `avs patterns` (the 500 Hz depth sequence) and `avs calib patterns` (the calibration one).
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace avs::cli {

/// Writes flash_image_NN.bmp (24 patterns per 24-bit BMP, projector::pack_flash_images) and
/// lut.csv (per LUT entry: the pattern's `labels` under the `label_header` columns, flash file,
/// flash image index from `first_flash_image`, pattern number and plane, trigger, buffer swap,
/// the 3 LUT bytes) to `dir`. Returns the number of flash images, or -1 when a file could not
/// be written.
int write_flash_images(const std::vector<std::vector<std::uint8_t>>& patterns,
                       const std::vector<std::string>& labels, const std::string& label_header,
                       int width, int height, int first_flash_image,
                       const std::filesystem::path& dir);

}  // namespace avs::cli
