// RAII file handles: an output file with a small staging buffer and a running CRC, and
// random-access sources (file or memory) for the reader. Internal to avs::mcap.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <span>

#include "avs/mcap/status.hpp"
#include "byte_buffer.hpp"

namespace avs::mcap::detail {

class UniqueFd {
 public:
  UniqueFd() = default;
  explicit UniqueFd(int fd) : fd_(fd) {}
  ~UniqueFd() { reset(); }
  UniqueFd(const UniqueFd&) = delete;
  UniqueFd& operator=(const UniqueFd&) = delete;
  UniqueFd(UniqueFd&& other) noexcept : fd_(other.release()) {}
  UniqueFd& operator=(UniqueFd&& other) noexcept {
    if (this != &other) {
      reset();
      fd_ = other.release();
    }
    return *this;
  }
  int get() const { return fd_; }
  int release() {
    int fd = fd_;
    fd_ = -1;
    return fd;
  }
  void reset();
  /// close(2) with its result (reset() ignores it).
  Status close(const std::filesystem::path& path);

 private:
  int fd_ = -1;
};

class OutputFile {
 public:
  Status open(const std::filesystem::path& path);
  bool is_open() const { return fd_.get() >= 0; }
  /// Appends; large writes bypass the staging buffer. Updates position() and the CRC.
  Status write(std::span<const std::byte> bytes);
  Status write(const ByteBuffer& bytes) { return write(bytes.span()); }
  /// As write(), when the caller already has the CRC-32 of `bytes` (saves a pass).
  Status write(std::span<const std::byte> bytes, std::uint32_t crc_of_bytes);
  Status flush();
  Status close();
  std::uint64_t position() const { return position_; }
  std::uint32_t crc() const { return crc_; }
  void reset_crc() { crc_ = 0; }
  void set_crc_enabled(bool enabled) { crc_enabled_ = enabled; }
  const std::filesystem::path& path() const { return path_; }

 private:
  Status write_direct(std::span<const std::byte> bytes);
  std::filesystem::path path_;
  UniqueFd fd_;
  ByteBuffer staging_;
  std::uint64_t position_ = 0;
  std::uint32_t crc_ = 0;
  bool crc_enabled_ = true;
};

/// Random access to the bytes of an MCAP file.
class Source {
 public:
  virtual ~Source() = default;
  virtual std::uint64_t size() const = 0;
  /// Makes `out` view bytes [offset, offset + length) (caller checked the range), copying
  /// into `scratch` if the source needs to.
  virtual Status view(std::uint64_t offset, std::uint64_t length, ByteBuffer& scratch,
                      std::span<const std::byte>& out) = 0;
};

Status open_file_source(const std::filesystem::path& path, std::unique_ptr<Source>& out);
std::unique_ptr<Source> make_memory_source(std::span<const std::byte> bytes);

}  // namespace avs::mcap::detail
