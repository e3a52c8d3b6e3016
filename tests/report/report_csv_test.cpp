// The run folder format: RunRecorder -> load_run round trip, and malformed files rejected
// with file:line errors.
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include "avs/report/run_data.hpp"
#include "avs/report/summary.hpp"
#include "synthetic_run.hpp"

namespace avs::report {
namespace {

namespace fs = std::filesystem;
using testing::TempDir;

std::string read_text(const fs::path& file) {
  std::ifstream in(file);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

void write_text(const fs::path& file, const std::string& text) {
  std::ofstream out(file, std::ios::trunc);
  out << text;
}

/// Writes a small valid run, then lets the test damage one line of frames.csv.
void write_run(const fs::path& dir, int frames = 20) {
  testing::SyntheticOptions options;
  options.frames = frames;
  options.init_frame = 3;
  RunRecorder recorder(dir, {"ken", "ken", "none", "synthetic, for tests"});
  for (const FrameRow& row : testing::make_frames(options)) recorder.write_frame(row);
}

/// Replaces line `line` (1-based) of `file` with `text`.
void replace_line(const fs::path& file, int line, const std::string& text) {
  std::istringstream in(read_text(file));
  std::string out, current;
  for (int n = 1; std::getline(in, current); ++n) out += (n == line ? text : current) + "\n";
  write_text(file, out);
}

std::string line_of(const fs::path& file, int line) {
  std::istringstream in(read_text(file));
  std::string current;
  for (int n = 1; std::getline(in, current); ++n) {
    if (n == line) return current;
  }
  return {};
}

/// load_run must throw a ReportError whose message contains `expected`.
void expect_error(const fs::path& dir, const std::string& expected) {
  try {
    (void)load_run(dir);
    ADD_FAILURE() << "no error; expected one containing: " << expected;
  } catch (const ReportError& e) {
    EXPECT_NE(std::string(e.what()).find(expected), std::string::npos)
        << "message: " << e.what() << "\nexpected to contain: " << expected;
  }
}

TEST(RunFiles, RoundTripKeepsEveryField) {
  TempDir tmp("round_trip");
  testing::SyntheticOptions options;
  options.frames = 300;
  const std::vector<FrameRow> frames = testing::make_frames(options);
  const std::vector<float> depth = testing::make_depth(32, 24);
  const std::vector<Eigen::Vector3d> scene{{0.1, 0.2, 0.8}, {0.11, 0.2, 0.81}};
  const std::vector<Eigen::Vector3d> model{{0.1, 0.21, 0.8}};
  {
    RunRecorder recorder(tmp.path(), {"cube", "cube", "cube", "notes, with a comma"});
    for (const FrameRow& row : frames) recorder.write_frame(row);
    recorder.write_depth_snapshot(1.5, 32, 24, depth);
    recorder.write_cloud_snapshot(1.1, scene, model);
    recorder.write_cloud_snapshot(1.2, model, scene);
    EXPECT_EQ(recorder.frames_written(), frames.size());
  }
  const RunData run = load_run(tmp.path());
  EXPECT_EQ(run.info.scenario, "cube");
  EXPECT_EQ(run.info.symmetry, "cube");
  EXPECT_EQ(run.info.notes, "notes, with a comma");
  ASSERT_EQ(run.frames.size(), frames.size());
  for (std::size_t i = 0; i < frames.size(); ++i) {
    const FrameRow& a = frames[i];
    const FrameRow& b = run.frames[i];
    ASSERT_EQ(a.t_s, b.t_s) << i;  // shortest round-trip formatting: exact
    ASSERT_EQ(a.centroid_px.has_value(), b.centroid_px.has_value()) << i;
    if (a.centroid_px) {
      EXPECT_EQ(*a.centroid_px, *b.centroid_px);
    }
    EXPECT_EQ(a.in_view, b.in_view);
    EXPECT_EQ(a.pan_rad, b.pan_rad);
    EXPECT_EQ(a.truth.p_world_m, b.truth.p_world_m);
    EXPECT_NEAR(a.truth.q_world.angularDistance(b.truth.q_world), 0.0, 1e-12);
    ASSERT_EQ(a.meas.has_value(), b.meas.has_value()) << i;
    if (a.meas) {
      EXPECT_EQ(a.meas->p_world_m, b.meas->p_world_m);
    }
    EXPECT_EQ(a.match_state, b.match_state);
    EXPECT_EQ(a.scene_points, b.scene_points);
    EXPECT_EQ(a.decode_ms, b.decode_ms);
    EXPECT_EQ(a.matching_ms, b.matching_ms);
  }
  ASSERT_TRUE(run.depth.has_value());
  EXPECT_EQ(run.depth->width, 32);
  EXPECT_EQ(run.depth->height, 24);
  ASSERT_EQ(run.depth->depth_m.size(), depth.size());
  EXPECT_EQ(run.depth->depth_m[400], depth[400]);
  ASSERT_EQ(run.clouds.size(), 2U);
  EXPECT_EQ(run.clouds[0].scene_m, scene);
  EXPECT_EQ(run.clouds[1].model_m, scene);
  EXPECT_DOUBLE_EQ(run.clouds[1].t_s, 1.2);
}

TEST(RunFiles, DerivedErrorColumnsMatchTheSummaryFunctions) {
  TempDir tmp("derived");
  write_run(tmp.path(), 50);
  const RunData run = load_run(tmp.path());
  std::istringstream in(read_text(tmp.path() / kFramesFile));
  std::string line;
  std::getline(in, line);  // header
  const Symmetry none = Symmetry::none();
  for (const FrameRow& row : run.frames) {
    std::getline(in, line);
    std::vector<std::string> fields;
    std::stringstream ss(line);
    for (std::string f; std::getline(ss, f, ',');) fields.push_back(f);
    if (line.back() == ',') fields.push_back("");
    ASSERT_EQ(fields.size(), frames_columns().size()) << line;
    if (!row.meas) {
      EXPECT_EQ(fields[26], "");
      continue;
    }
    EXPECT_NEAR(std::stod(fields[26]), position_error_mm(row.truth, *row.meas), 1e-9);
    EXPECT_NEAR(std::stod(fields[27]),
                orientation_error_deg(row.truth.q_world, row.meas->q_world, none), 1e-9);
  }
}

TEST(RunFiles, WrongFieldCountNamesFileAndLine) {
  TempDir tmp("field_count");
  write_run(tmp.path());
  replace_line(tmp.path() / kFramesFile, 7, line_of(tmp.path() / kFramesFile, 7) + ",42");
  expect_error(tmp.path(), "frames.csv:7: expected 29 fields (as in the header), got 30");
}

TEST(RunFiles, BadNumberNamesFileLineAndColumn) {
  TempDir tmp("bad_number");
  write_run(tmp.path());
  std::string line = line_of(tmp.path() / kFramesFile, 5);
  // pan_rad is the sixth field.
  std::vector<std::string> fields;
  std::stringstream ss(line);
  for (std::string f; std::getline(ss, f, ',');) fields.push_back(f);
  std::size_t start = 0;
  for (int i = 0; i < 5; ++i) start = line.find(',', start) + 1;
  const std::size_t end = line.find(',', start);
  line.replace(start, end - start, "abc");
  replace_line(tmp.path() / kFramesFile, 5, line);
  expect_error(tmp.path(), "frames.csv:5: column 'pan_rad': cannot parse 'abc' as a number");
}

TEST(RunFiles, RowCutShortByAKilledWriterIsDroppedWithAWarning) {
  TempDir tmp("cut_short");
  write_run(tmp.path(), 20);
  std::string text = read_text(tmp.path() / kFramesFile);
  text += "1.04,3.5,";  // a 22nd row cut off mid-write, no newline
  write_text(tmp.path() / kFramesFile, text);
  const RunData run = load_run(tmp.path());
  EXPECT_EQ(run.frames.size(), 20U);
  ASSERT_EQ(run.warnings.size(), 1U);
  EXPECT_NE(run.warnings[0].find("frames.csv:22: last line is cut short"), std::string::npos)
      << run.warnings[0];
  // The same row with its newline is a malformed row, not a cut one.
  write_text(tmp.path() / kFramesFile, text + "\n");
  expect_error(tmp.path(), "frames.csv:22: expected 29 fields (as in the header), got 3");
}

TEST(RunFiles, AFolderFromBeforeTheWallClockColumnStillLoads) {
  TempDir tmp("without_wall_s");
  write_run(tmp.path(), 20);
  // Drop the last column (wall_s) from every line, as older recorders wrote them.
  std::istringstream in(read_text(tmp.path() / kFramesFile));
  std::string old;
  for (std::string line; std::getline(in, line);) old += line.substr(0, line.rfind(',')) + "\n";
  ASSERT_EQ(old.find("wall_s"), std::string::npos);
  write_text(tmp.path() / kFramesFile, old);
  const RunData run = load_run(tmp.path());
  ASSERT_EQ(run.frames.size(), 20U);
  EXPECT_FALSE(run.frames.front().wall_s.has_value());
}

TEST(RunFiles, MissingColumnIsReportedOnTheHeaderLine) {
  TempDir tmp("missing_column");
  write_run(tmp.path());
  std::string header = line_of(tmp.path() / kFramesFile, 1);
  header.replace(header.find("tilt_rad"), 8, "tilt_deg");
  replace_line(tmp.path() / kFramesFile, 1, header);
  expect_error(tmp.path(), "frames.csv:1: missing column 'tilt_rad'");
}

TEST(RunFiles, UnknownMatchStateAndInconsistentRowsAreRejected) {
  {
    TempDir tmp("match_state");
    write_run(tmp.path());
    std::string line = line_of(tmp.path() / kFramesFile, 9);
    line.replace(line.find(",tracking,"), 10, ",matching,");
    replace_line(tmp.path() / kFramesFile, 9, line);
    expect_error(tmp.path(), "frames.csv:9: column 'match_state': unknown match_state 'matching'");
  }
  {
    TempDir tmp("time_backwards");
    write_run(tmp.path());
    std::string line = line_of(tmp.path() / kFramesFile, 12);
    line.replace(0, line.find(','), "0.5");
    replace_line(tmp.path() / kFramesFile, 12, line);
    expect_error(tmp.path(), "frames.csv:12: column 't_s': time goes backwards");
  }
  {
    TempDir tmp("partial_pose");
    write_run(tmp.path());
    const RunData run = load_run(tmp.path());
    ASSERT_TRUE(run.frames[10].meas.has_value());  // line 12
    std::string line = line_of(tmp.path() / kFramesFile, 12);
    std::size_t start = 0;
    for (int i = 0; i < 14; ++i) start = line.find(',', start) + 1;  // meas_x_m is field 15
    line.erase(start, line.find(',', start) - start);
    replace_line(tmp.path() / kFramesFile, 12, line);
    expect_error(tmp.path(),
                 "frames.csv:12: column 'meas_x_m': empty in a pose that is partly given");
  }
  {
    TempDir tmp("quaternion_norm");
    write_run(tmp.path());
    std::string line = line_of(tmp.path() / kFramesFile, 4);
    std::size_t start = 0;
    for (int i = 0; i < 10; ++i) start = line.find(',', start) + 1;  // true_qw is field 11
    line.replace(start, line.find(',', start) - start, "2");
    replace_line(tmp.path() / kFramesFile, 4, line);
    expect_error(tmp.path(), "frames.csv:4: column 'true_qw': quaternion norm");
  }
}

TEST(RunFiles, MissingFilesAndBadSnapshotsAreNamed) {
  TempDir tmp("missing");
  expect_error(tmp.path(), "meta.csv: cannot open for reading");
  write_run(tmp.path());
  write_text(tmp.path() / kDepthSnapshotFile,
             "t_s,width,height,file\n1,10,10,depth_snapshot.f32\n");
  write_text(tmp.path() / kDepthSnapshotRawFile, "short");
  expect_error(tmp.path(), "depth_snapshot.f32: expected 400 bytes (10 x 10 float32), got 5");
  std::filesystem::remove(tmp.path() / kDepthSnapshotFile);
  write_text(tmp.path() / kCloudsSnapshotFile,
             "snapshot,t_s,cloud,x_m,y_m,z_m\n0,1,scene,1,2,3\n0,1,mesh,1,2,3\n");
  expect_error(tmp.path(),
               "clouds_snapshot.csv:3: column 'cloud': expected 'scene' or 'model', got 'mesh'");
  write_text(tmp.path() / kMetaFile, "key,value\nsymmetry,sphere\n");
  expect_error(tmp.path(), "meta.csv: unknown symmetry 'sphere'");
}

TEST(RunRecorder, RejectsBadInput) {
  TempDir tmp("recorder");
  EXPECT_THROW(RunRecorder(tmp.path(), {"x", "y", "dodecahedron", ""}), ReportError);
  RunRecorder recorder(tmp.path(), {.scenario = "ken", .object = "ken", .symmetry = "none"});
  FrameRow row;
  row.t_s = 2.0;
  recorder.write_frame(row);
  row.t_s = 1.0;
  EXPECT_THROW(recorder.write_frame(row), ReportError);
  const std::vector<float> depth(10);
  EXPECT_THROW(recorder.write_depth_snapshot(0.0, 4, 4, depth), ReportError);
  EXPECT_THROW(recorder.write_cloud_snapshot(0.0, {}, {}), ReportError);
}

}  // namespace
}  // namespace avs::report
