// make_report on a synthetic run: gnuplot is really run; the PNGs are decoded (libpng) and
// checked for the colours of their data; index.html must reference every figure made.
#include <gtest/gtest.h>
#include <png.h>

#include <fstream>
#include <set>
#include <sstream>

#include "avs/report/paper.hpp"
#include "avs/report/report.hpp"
#include "avs/report/table.hpp"
#include "synthetic_run.hpp"

namespace avs::report {
namespace {

namespace fs = std::filesystem;
using testing::TempDir;

struct Rgb {
  int r, g, b;
};

struct Image {
  int width = 0, height = 0;
  std::vector<unsigned char> rgb;
  /// Pixels within `tolerance` of `colour` in every channel.
  int count(Rgb colour, int tolerance = 12) const {
    int n = 0;
    for (std::size_t i = 0; i + 2 < rgb.size(); i += 3) {
      if (std::abs(rgb[i] - colour.r) <= tolerance &&
          std::abs(rgb[i + 1] - colour.g) <= tolerance &&
          std::abs(rgb[i + 2] - colour.b) <= tolerance) {
        ++n;
      }
    }
    return n;
  }
};

Image decode_png(const fs::path& file) {
  png_image png{};
  png.version = PNG_IMAGE_VERSION;
  if (png_image_begin_read_from_file(&png, file.c_str()) == 0) {
    ADD_FAILURE() << file << ": " << png.message;
    return {};
  }
  png.format = PNG_FORMAT_RGB;
  Image image;
  image.width = static_cast<int>(png.width);
  image.height = static_cast<int>(png.height);
  image.rgb.resize(PNG_IMAGE_SIZE(png));
  if (png_image_finish_read(&png, nullptr, image.rgb.data(), 0, nullptr) == 0) {
    ADD_FAILURE() << file << ": " << png.message;
  }
  return image;
}

std::string read_text(const fs::path& file) {
  std::ifstream in(file);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

void write_full_run(const fs::path& dir, const testing::SyntheticOptions& options, bool snapshots) {
  RunRecorder recorder(dir, {"demo", "ken", "none", ""});
  const std::vector<FrameRow> frames = testing::make_frames(options);
  for (const FrameRow& row : frames) recorder.write_frame(row);
  if (!snapshots) return;
  recorder.write_depth_snapshot(1.2, 128, 96, testing::make_depth(128, 96));
  for (int k = 0; k < 6; ++k) {
    std::vector<Eigen::Vector3d> scene, model;
    for (int i = 0; i < 300; ++i) {
      const double a = i * 0.05 + k, b = i * 0.11;
      scene.emplace_back(0.05 * std::cos(a) * std::sin(b), 0.05 * std::sin(a) * std::sin(b),
                         0.8 + 0.05 * std::cos(b));
      model.push_back(scene.back() + Eigen::Vector3d(0.002, 0.0, 0.0));
    }
    recorder.write_cloud_snapshot(1.0 + 0.3 * k, scene, model);
  }
}

const Rgb kRed{0xd6, 0x27, 0x28};
const Rgb kBlue{0x1f, 0x77, 0xb4};

TEST(Report, MakesEveryFigureWithDataAndAPageThatShowsThem) {
  TempDir tmp("full");
  write_full_run(tmp.path(), {}, true);
  ReportOptions options;
  options.plots.width_px = 900;
  options.plots.height_px = 600;
  const Report report = make_report(tmp.path(), options);

  ASSERT_TRUE(report.plots.failed.empty()) << report.plots.failed.front().reason;
  EXPECT_TRUE(report.plots.skipped.empty());
  const std::set<std::string> expected{
      "fig8_centroid_error.png",   "fig9_depth.png",   "fig10_centroid_trajectory.png",
      "fig13_points_and_time.png", "fig14_clouds.png", "fig15_position.png",
      "fig16_quaternion.png",      "pose_error.png"};
  std::set<std::string> made;
  for (const Plot& plot : report.plots.made) made.insert(plot.png);
  EXPECT_EQ(made, expected);

  const std::string html = read_text(report.index_html);
  for (const std::string& png : expected) {
    SCOPED_TRACE(png);
    int width = 0, height = 0;
    ASSERT_TRUE(read_png_size(tmp.path() / png, width, height));
    EXPECT_EQ(width, 900);
    EXPECT_EQ(height, 600);
    EXPECT_NE(html.find("<img src=\"" + png + "\""), std::string::npos);
    const Image image = decode_png(tmp.path() / png);
    ASSERT_EQ(image.width, 900);
    // Not blank: the data series colours cover a visible area.
    const int data_pixels = png == "fig9_depth.png"
                                ? image.count({255, 0, 0}, 40) + image.count({0, 0, 255}, 40)
                                : image.count(kRed) + image.count(kBlue);
    EXPECT_GT(data_pixels, 500) << "figure looks empty";
  }
  // Figure 9: near (red), far (blue) and invalid (black) all present.
  const Image depth = decode_png(tmp.path() / "fig9_depth.png");
  EXPECT_GT(depth.count({255, 0, 0}, 40), 1000);
  EXPECT_GT(depth.count({0, 0, 255}, 60), 1000);
  EXPECT_GT(depth.count({0, 0, 0}, 5), 5000);

  // The page carries our numbers from this run, beside the paper's.
  EXPECT_NE(html.find(format_figure(report.summary.position_error_mm_rms)), std::string::npos);
  EXPECT_NE(html.find("<td class=\"num\">148</td>"), std::string::npos);
  EXPECT_NE(html.find("real-time factor 0.2)"), std::string::npos);  // 5 s of wall per sim s
  EXPECT_NE(html.find("<th>verdict</th>"), std::string::npos);
  // Fig. 10(b): tick steps chosen for the data's span (gnuplot's own crowd the 3-D panel).
  const std::string fig10 = read_text(tmp.path() / "gnuplot/fig10_centroid_trajectory.gp");
  // X spans 0.2 m and Y 0.1 m: at most 4 ticks are steps of 0.1 and 0.05.
  EXPECT_NE(fig10.find("set xtics 0.1\nset ytics 0.05 offset"), std::string::npos) << fig10;
  const std::string json = read_text(report.summary_json);
  EXPECT_NE(json.find("\"scenario\": \"demo\""), std::string::npos);
  EXPECT_NE(json.find("\"flips\": 4"), std::string::npos) << json;
  // Scripts are kept for re-making a figure by hand.
  EXPECT_TRUE(fs::exists(tmp.path() / "gnuplot" / "fig8_centroid_error.gp"));
}

TEST(Report, FiguresWithoutDataAreListedNotFaked) {
  TempDir tmp("no_poses");
  testing::SyntheticOptions options;
  options.with_poses = false;
  write_full_run(tmp.path(), options, false);
  std::ostringstream out, err;
  ASSERT_EQ(report_main(tmp.path(), out, err), 0) << err.str();
  const std::string html = read_text(tmp.path() / kIndexFile);
  for (const char* png :
       {"fig15_position.png", "fig16_quaternion.png", "fig9_depth.png", "fig14_clouds.png"}) {
    EXPECT_FALSE(fs::exists(tmp.path() / png)) << png;
    EXPECT_EQ(html.find(std::string("<img src=\"") + png), std::string::npos) << png;
    EXPECT_NE(html.find(std::string("<code>") + png + "</code>: no data"), std::string::npos)
        << png;
  }
  EXPECT_TRUE(fs::exists(tmp.path() / "fig8_centroid_error.png"));
  EXPECT_NE(out.str().find("depth update rate"), std::string::npos) << out.str();
  EXPECT_NE(out.str().find("report: "), std::string::npos);
}

TEST(Report, GnuplotFailureIsReportedWithItsStatus) {
  TempDir tmp("gnuplot_fails");
  write_full_run(tmp.path(), {}, false);
  ReportOptions options;
  options.plots.gnuplot_program = "false";  // exits 1 without output
  const Report report = make_report(tmp.path(), options);
  EXPECT_TRUE(report.plots.made.empty());
  ASSERT_FALSE(report.plots.failed.empty());
  EXPECT_NE(report.plots.failed.front().reason.find("exited with status 1"), std::string::npos)
      << report.plots.failed.front().reason;
  EXPECT_NE(read_text(report.index_html).find("FAILED"), std::string::npos);

  options.plots.gnuplot_program = "avs-no-such-gnuplot";
  EXPECT_THROW((void)make_report(tmp.path(), options), ReportError);
}

TEST(Report, GnuplotErrorTextReachesTheCaller) {
  TempDir tmp("gnuplot_stderr");
  std::ofstream(tmp.path() / "bad.gp") << "plot 'no_such_file.csv' using 1:2\n";
  try {
    (void)run_gnuplot(tmp.path(), "bad.gp");
    FAIL() << "gnuplot accepted a missing data file";
  } catch (const ReportError& e) {
    EXPECT_NE(std::string(e.what()).find("no_such_file.csv"), std::string::npos) << e.what();
  }
}

TEST(Report, MalformedRunGivesFileLineOnStderr) {
  TempDir tmp("malformed");
  write_full_run(tmp.path(), {}, false);
  std::ofstream(tmp.path() / kFramesFile, std::ios::app) << "1,2,3\n";
  std::ostringstream out, err;
  EXPECT_EQ(report_main(tmp.path(), out, err), 1);
  EXPECT_NE(err.str().find("frames.csv:1002: expected 29 fields"), std::string::npos) << err.str();
}

TEST(Tables, ComparisonTableHasThePapersFiguresAndOurs) {
  Summary s;
  s.init_ms = 93.5;
  s.pose_rate_hz = 490.25;
  s.depth_rate_hz = 500;
  const std::string text = format_comparison_table("cube", s);
  EXPECT_NE(text.find("93.98"), std::string::npos) << text;
  EXPECT_NE(text.find("93.5"), std::string::npos) << text;
  EXPECT_NE(text.find("487"), std::string::npos) << text;
  EXPECT_NE(text.find("490.2"), std::string::npos) << text;
  EXPECT_NE(text.find("7.2.2"), std::string::npos) << text;
  for (const std::string& scenario : known_scenarios()) {
    EXPECT_FALSE(comparison_rows(scenario, s).empty()) << scenario;
  }
  for (const PaperFigure& figure : paper_figures()) {
    EXPECT_NO_THROW((void)summary_value(s, figure.key)) << figure.key;
  }
  const std::string markdown = format_comparison_markdown("cube", s);
  EXPECT_EQ(
      markdown.rfind("| figure | statistic | clock | paper | ours | unit | verdict | section |", 0),
      0U)
      << markdown;
  EXPECT_NE(
      markdown.find(
          "| initial alignment | first | wall | 93.98 | 93.5 | ms | pass (< 93.98) | 7.2.2 |"),
      std::string::npos)
      << markdown;
  // 490.25 Hz against the paper's 487: a pass within 1 % (>= 482.1).
  EXPECT_NE(markdown.find("| ICP rate | mean rate | sim | 487 | 490.2 | Hz | pass (>= 482.1) |"),
            std::string::npos)
      << markdown;
  const std::string json = experiments_json({{"ken", s}, {"cube", s}});
  EXPECT_EQ(json.rfind("{\"ken\": {\"scenario\": \"ken\"", 0), 0U) << json;
  EXPECT_NE(json.find(", \"cube\": {"), std::string::npos) << json;
}

TEST(Tables, VerdictsAgainstThePapersLimits) {
  EXPECT_EQ(verdict(below(2), 1.85), "pass (< 2)");
  EXPECT_EQ(verdict(below(1.5), 2.717), "FAIL (< 1.5)");
  EXPECT_EQ(verdict(below(1.5), 1.5), "FAIL (< 1.5)");  // "less than" is strict
  EXPECT_EQ(verdict(rate_of(500), 499.0), "pass (>= 495)");
  EXPECT_EQ(verdict(rate_of(500), 492.0), "FAIL (>= 495)");
  EXPECT_EQ(verdict(at_least(1), 1.0), "pass (>= 1)");
  EXPECT_EQ(verdict(below(2), kUndefined), "-");
  EXPECT_EQ(verdict(PaperLimit{}, 3.0), "");

  // In the table: the demo's pair-time row fails when the 99th percentile is over 2 ms, and
  // a row without a paper limit says "-".
  Summary s;
  s.depth_rate_hz = 500;
  s.decode_ms_p99 = 2.4;
  s.decode_ms_median = 1.1;
  const auto rows = comparison_rows("demo", s);
  const auto row = [&](const std::string& key) {
    for (const ComparisonRow& r : rows) {
      if (r.key == key) return r;
    }
    ADD_FAILURE() << key;
    return ComparisonRow{};
  };
  EXPECT_EQ(row("decode_ms_p99").verdict, "FAIL (< 2)");
  EXPECT_EQ(row("decode_ms_p99").statistic, "p99");
  EXPECT_EQ(row("decode_ms_p99").clock, "wall");
  EXPECT_EQ(row("decode_ms_median").verdict, "");
  EXPECT_EQ(row("decode_ms_median").paper, "about 1.5 (GPU)");
  EXPECT_EQ(row("depth_rate_hz").verdict, "pass (>= 495)");
  EXPECT_EQ(row("depth_rate_hz").clock, "sim");
  const std::string text = format_comparison_table("demo", s);
  EXPECT_NE(text.find("FAIL (< 2)"), std::string::npos) << text;

  s.duration_s = 3.0;
  s.wall_duration_s = 15.0;
  s.real_time_factor = 0.2;
  const std::string clocks = format_run_clocks(s);
  EXPECT_NE(clocks.find("3 s of simulated time in 15 s of wall-clock time (real-time factor 0.2)"),
            std::string::npos)
      << clocks;
  EXPECT_NE(format_run_clocks(Summary{}).find("real-time factor unknown"), std::string::npos);
}

TEST(Tables, TextTableAlignsColumns) {
  TextTable table({"a", "bb"});
  table.add_row({"long label", "1.5"});
  table.add_row({"x", "100"});
  EXPECT_EQ(table.render(), "a            bb\n---------------\nlong label  1.5\nx           100\n");
  TextTable mixed({"k", "v"});
  mixed.add_row({"a", "about 1"});
  mixed.add_row({"b", "2"});
  EXPECT_EQ(mixed.render(), "k  v\n----------\na  about 1\nb  2\n");
  EXPECT_THROW(table.add_row({"one"}), ReportError);
  EXPECT_EQ(format_figure(kUndefined), "-");
  EXPECT_EQ(format_figure(500.0), "500");
  EXPECT_EQ(format_figure(1.23456), "1.235");
}

}  // namespace
}  // namespace avs::report
