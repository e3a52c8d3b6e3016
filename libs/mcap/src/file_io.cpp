#include "file_io.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <string>

#include "checksum.hpp"

namespace avs::mcap::detail {

namespace {

constexpr std::size_t kStagingBytes = 64 * 1024;

Status errno_status(const char* what, const std::filesystem::path& path) {
  return Status(StatusCode::io_error,
                std::string(what) + " " + path.string() + ": " + std::strerror(errno));
}

}  // namespace

void UniqueFd::reset() {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
}

Status UniqueFd::close(const std::filesystem::path& path) {
  int fd = release();
  if (fd >= 0 && ::close(fd) != 0) return errno_status("close", path);
  return {};
}

Status OutputFile::open(const std::filesystem::path& path) {
  path_ = path;
  int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) return errno_status("cannot create", path);
  fd_ = UniqueFd(fd);
  staging_.reserve(kStagingBytes);
  position_ = 0;
  crc_ = 0;
  return {};
}

Status OutputFile::write_direct(std::span<const std::byte> bytes) {
  while (!bytes.empty()) {
    ssize_t n = ::write(fd_.get(), bytes.data(), bytes.size());
    if (n < 0) {
      if (errno == EINTR) continue;
      return errno_status("write", path_);
    }
    bytes = bytes.subspan(static_cast<std::size_t>(n));
  }
  return {};
}

Status OutputFile::write(std::span<const std::byte> bytes, std::uint32_t crc_of_bytes) {
  if (crc_enabled_) crc_ = crc32_combine(crc_, crc_of_bytes, bytes.size());
  const bool enabled = crc_enabled_;
  crc_enabled_ = false;
  Status s = write(bytes);
  crc_enabled_ = enabled;
  return s;
}

Status OutputFile::write(std::span<const std::byte> bytes) {
  if (!is_open()) return Status(StatusCode::invalid_argument, "write to a closed file");
  if (crc_enabled_) crc_ = crc32_update(crc_, bytes);
  position_ += bytes.size();
  if (staging_.size() + bytes.size() <= kStagingBytes) {
    staging_.append(bytes);
    return {};
  }
  if (Status s = flush(); !s.ok()) return s;
  if (bytes.size() >= kStagingBytes) return write_direct(bytes);
  staging_.append(bytes);
  return {};
}

Status OutputFile::flush() {
  if (staging_.empty()) return {};
  Status s = write_direct(staging_.span());
  staging_.clear();
  return s;
}

Status OutputFile::close() {
  if (!is_open()) return {};
  Status flushed = flush();
  Status closed = fd_.close(path_);
  return flushed.ok() ? closed : flushed;
}

namespace {

class FileSource final : public Source {
 public:
  FileSource(UniqueFd fd, std::uint64_t size, std::filesystem::path path)
      : fd_(std::move(fd)), size_(size), path_(std::move(path)) {}
  std::uint64_t size() const override { return size_; }
  Status view(std::uint64_t offset, std::uint64_t length, ByteBuffer& scratch,
              std::span<const std::byte>& out) override {
    scratch.resize_uninitialized(static_cast<std::size_t>(length));
    std::size_t done = 0;
    while (done < length) {
      ssize_t n = ::pread(fd_.get(), scratch.data() + done, length - done,
                          static_cast<off_t>(offset + done));
      if (n < 0) {
        if (errno == EINTR) continue;
        return errno_status(("read at offset " + std::to_string(offset + done) + " of").c_str(),
                            path_);
      }
      if (n == 0) {
        return Status(StatusCode::truncated, "file " + path_.string() + " ended at offset " +
                                                 std::to_string(offset + done) +
                                                 " while reading (it shrank?)");
      }
      done += static_cast<std::size_t>(n);
    }
    out = scratch.span();
    return {};
  }

 private:
  UniqueFd fd_;
  std::uint64_t size_;
  std::filesystem::path path_;
};

class MemorySource final : public Source {
 public:
  explicit MemorySource(std::span<const std::byte> bytes) : bytes_(bytes) {}
  std::uint64_t size() const override { return bytes_.size(); }
  Status view(std::uint64_t offset, std::uint64_t length, ByteBuffer&,
              std::span<const std::byte>& out) override {
    out = bytes_.subspan(static_cast<std::size_t>(offset), static_cast<std::size_t>(length));
    return {};
  }

 private:
  std::span<const std::byte> bytes_;
};

}  // namespace

Status open_file_source(const std::filesystem::path& path, std::unique_ptr<Source>& out) {
  int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return errno_status("cannot open", path);
  UniqueFd owned(fd);
  struct stat info {};
  if (::fstat(fd, &info) != 0) return errno_status("fstat", path);
  out = std::make_unique<FileSource>(std::move(owned), static_cast<std::uint64_t>(info.st_size),
                                     path);
  return {};
}

std::unique_ptr<Source> make_memory_source(std::span<const std::byte> bytes) {
  return std::make_unique<MemorySource>(bytes);
}

}  // namespace avs::mcap::detail
