// A test program's scratch directory: <temp>/<prefix><pid>, created on construction, removed with
// everything in it on destruction when the program's tests passed so far. Tests that write
// recordings leave nothing behind (a bag test's closed-loop recording is half a gigabyte; left in
// /tmp by every run they filled the CI machine's disk). After a failure the files are kept and
// the path printed, because the logs in them are what explains the failure.
#pragma once

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <string>
#include <system_error>

namespace avs::testing {

class ScratchDir {
 public:
  explicit ScratchDir(const std::string& prefix)
      : path_(std::filesystem::temp_directory_path() / (prefix + std::to_string(::getpid()))) {
    std::filesystem::create_directories(path_);
  }
  ~ScratchDir() {
    if (::testing::UnitTest::GetInstance()->Failed()) {
      std::fprintf(stderr, "test files kept for inspection: %s\n", path_.c_str());
      return;
    }
    std::error_code ignored;  // best effort: a test must not fail on cleaning up
    std::filesystem::remove_all(path_, ignored);
  }
  ScratchDir(const ScratchDir&) = delete;
  ScratchDir& operator=(const ScratchDir&) = delete;

  const std::filesystem::path& path() const { return path_; }
  std::filesystem::path operator/(const std::string& name) const { return path_ / name; }

 private:
  std::filesystem::path path_;
};

}  // namespace avs::testing
