// avs report DIR: re-makes a run folder's report (summary.json, figures, index.html) from its
// CSV data and prints the results table. The library is libs/report (docs/report.md).
#include <iostream>

#include "commands.hpp"

#if __has_include("avs/report/report.hpp")
#include "avs/report/report.hpp"
#define AVS_HAVE_REPORT 1
#endif

namespace avs::cli {

namespace {

void add_report_command(Command& app) {
  auto* cmd = app.add_subcommand(
      "report",
      "Make the report of a run folder (figures, index.html, summary.json) from its CSV data");
  static std::string dir;
  static int width_px = 1000;
  static int height_px = 650;
  static std::string gnuplot = "gnuplot";
  cmd->add_option("DIR", dir, "run folder (frames.csv, meta.csv, ...)")->required();
  cmd->add_option("--width", width_px, "figure width in pixels")
      ->capture_default_str()
      ->check_range(100, 10000);
  cmd->add_option("--height", height_px, "figure height in pixels")
      ->capture_default_str()
      ->check_range(100, 10000);
  cmd->add_option("--gnuplot", gnuplot, "gnuplot program")->capture_default_str();
  cmd->callback([] {
#ifdef AVS_HAVE_REPORT
    avs::report::ReportOptions options;
    options.plots.width_px = width_px;
    options.plots.height_px = height_px;
    options.plots.gnuplot_program = gnuplot;
    exit_status() = avs::report::report_main(dir, std::cout, std::cerr, options);
#else
    std::cerr << "avs report: this avs was built without libs/report\n";
    exit_status() = 1;
#endif
  });
}

}  // namespace

AVS_REGISTER_COMMAND(add_report_command)

}  // namespace avs::cli
