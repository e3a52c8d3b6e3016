// The report's pictures: one generated gnuplot script per figure (kept in <run>/gnuplot/ so a
// figure can be re-made or restyled by hand), run as a child process in the run folder,
// reading the run's CSV files. No drawing code of our own.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "avs/report/run_data.hpp"

namespace avs::report {

struct PlotConfig {
  std::string gnuplot_program = "gnuplot";  ///< looked up in PATH
  int width_px = 1000;
  int height_px = 650;
};

struct Plot {
  std::string png;             ///< file name in the run folder, e.g. "fig8_centroid_error.png"
  std::string script;          ///< "gnuplot/fig8_centroid_error.gp"
  std::string title;           ///< "Error in the image plane"
  std::string caption;         ///< what it shows and which paper figure it mirrors
  std::string gnuplot_stderr;  ///< warnings gnuplot printed (empty when none)
};

struct SkippedPlot {
  std::string png;
  std::string reason;  ///< "no frame has a pose estimate"
};

struct PlotResult {
  std::vector<Plot> made;
  std::vector<SkippedPlot> skipped;  ///< no data for it in this run
  std::vector<SkippedPlot> failed;   ///< gnuplot failed: reason holds its exit status and stderr
};

/// Writes the scripts and runs gnuplot for every figure the run has data for:
/// fig8_centroid_error, fig9_depth, fig10_centroid_trajectory, fig13_points_and_time,
/// fig14_clouds, fig15_position, fig16_quaternion (.png in run.dir).
/// Throws ReportError only when gnuplot cannot be started at all.
[[nodiscard]] PlotResult make_plots(const RunData& run, const PlotConfig& config = {});

/// Runs `gnuplot <script>` with `working_dir` as its current directory. Returns gnuplot's
/// stderr. Throws ReportError with the exit status and stderr when it does not exit 0.
std::string run_gnuplot(const std::filesystem::path& working_dir, const std::string& script,
                        const PlotConfig& config = {});

/// True when `file` starts with the PNG signature and an IHDR chunk; sets width and height.
[[nodiscard]] bool read_png_size(const std::filesystem::path& file, int& width, int& height);

}  // namespace avs::report
