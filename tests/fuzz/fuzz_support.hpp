// Helpers of the libFuzzer targets (tests/fuzz): the input as text or as a file in a scratch
// folder, and the check that an error a parser reports for outside input names where it is.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>

namespace avs::fuzz {

inline std::string text_of(const std::uint8_t* data, std::size_t size) {
  return {reinterpret_cast<const char*>(data), size};
}

/// A private folder under $TMPDIR for the parsers that read files, removed at exit.
class ScratchDir {
 public:
  ScratchDir() {
    std::string pattern = (std::filesystem::temp_directory_path() / "avs_fuzz_XXXXXX").string();
    if (::mkdtemp(pattern.data()) == nullptr) {
      std::perror("mkdtemp");
      std::abort();
    }
    path_ = pattern;
  }
  ~ScratchDir() {
    std::error_code ignored;
    std::filesystem::remove_all(path_, ignored);
  }
  ScratchDir(const ScratchDir&) = delete;
  ScratchDir& operator=(const ScratchDir&) = delete;

  /// Writes `bytes` to `name` in the folder; returns its path.
  std::string write(const std::string& name, std::string_view bytes) const {
    const std::string file = (path_ / name).string();
    std::ofstream out(file, std::ios::binary | std::ios::trunc);
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    if (!out) {
      std::fprintf(stderr, "cannot write %s\n", file.c_str());
      std::abort();
    }
    return file;
  }
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

/// Every error about outside input names its source ("file:line:col: what" or "file: what");
/// anything else (a bare yaml-cpp or std:: message) is a finding: abort so libFuzzer keeps it.
inline void expect_located(const std::exception& error, std::string_view source) {
  const std::string_view what = error.what();
  if (what.substr(0, source.size()) == source && what.size() > source.size() &&
      what[source.size()] == ':') {
    return;
  }
  std::fprintf(stderr, "error without location (expected \"%.*s:...\"): %s\n",
               static_cast<int>(source.size()), source.data(), error.what());
  std::abort();
}

}  // namespace avs::fuzz
