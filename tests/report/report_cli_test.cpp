// `avs report DIR` as wired by tools/avs/report_cmd.cpp (registered with AVS_REGISTER_COMMAND),
// driven through the CLI11 facade (tools/avs/command.hpp) here without the whole avs program.
#include <gtest/gtest.h>

#include <CLI/CLI.hpp>

#include "avs/report/plots.hpp"
#include "avs/report/run_data.hpp"
#include "commands.hpp"
#include "synthetic_run.hpp"

namespace avs::cli {
int& exit_status() {
  static int status = 0;
  return status;
}
}  // namespace avs::cli

namespace avs::report {
namespace {

int run_cli(std::vector<std::string> words) {
  avs::cli::Command app{"avs"};
  app.require_subcommand(1);
  for (const auto& [name, adder] : avs::cli::registered_commands()) {
    if (name == "add_report_command") adder(app);
  }
  std::vector<const char*> argv{"avs"};
  for (const auto& w : words) argv.push_back(w.c_str());
  avs::cli::exit_status() = -1;
  app.parse(static_cast<int>(argv.size()), argv.data());
  return avs::cli::exit_status();
}

TEST(ReportCommand, MakesTheReportOfARunFolder) {
  testing::TempDir tmp("cli");
  {
    RunRecorder recorder(tmp.path(), {"ken", "ken", "none", ""});
    testing::SyntheticOptions options;
    options.frames = 200;
    for (const FrameRow& row : testing::make_frames(options)) recorder.write_frame(row);
  }
  EXPECT_EQ(run_cli({"report", tmp.path().string(), "--width", "640", "--height", "480"}), 0);
  int width = 0, height = 0;
  ASSERT_TRUE(read_png_size(tmp.path() / "fig15_position.png", width, height));
  EXPECT_EQ(width, 640);
  EXPECT_EQ(height, 480);
  EXPECT_TRUE(std::filesystem::exists(tmp.path() / kIndexFile));
}

TEST(ReportCommand, MakesTheFiguresOfAFolderGivenRelativeToTheWorkingDirectory) {
  testing::TempDir tmp("cli_relative");
  {
    RunRecorder recorder(tmp.path(), {"ken", "ken", "none", ""});
    testing::SyntheticOptions options;
    options.frames = 100;
    for (const FrameRow& row : testing::make_frames(options)) recorder.write_frame(row);
  }
  // gnuplot runs inside the run folder: a relative folder name must still resolve.
  const auto previous = std::filesystem::current_path();
  std::filesystem::current_path(tmp.path().parent_path());
  const int status = run_cli({"report", tmp.path().filename().string()});
  std::filesystem::current_path(previous);
  EXPECT_EQ(status, 0);
  EXPECT_TRUE(std::filesystem::exists(tmp.path() / "fig15_position.png"));
}

TEST(ReportCommand, FailsOnAFolderWithoutData) {
  testing::TempDir tmp("cli_empty");
  EXPECT_EQ(run_cli({"report", tmp.path().string()}), 1);
  EXPECT_THROW(run_cli({"report"}), CLI::ParseError);
}

}  // namespace
}  // namespace avs::report
