// Growable byte buffer without zero-filling (std::vector::resize would touch every byte once
// more at 262 MB/s). Internal to avs::mcap.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <memory>
#include <span>

namespace avs::mcap::detail {

class ByteBuffer {
 public:
  ByteBuffer() = default;
  ByteBuffer(const ByteBuffer&) = delete;
  ByteBuffer& operator=(const ByteBuffer&) = delete;
  ByteBuffer(ByteBuffer&&) noexcept = default;
  ByteBuffer& operator=(ByteBuffer&&) noexcept = default;

  std::byte* data() { return data_.get(); }
  const std::byte* data() const { return data_.get(); }
  std::size_t size() const { return size_; }
  std::size_t capacity() const { return capacity_; }
  bool empty() const { return size_ == 0; }
  std::span<const std::byte> span() const { return {data_.get(), size_}; }

  void clear() { size_ = 0; }
  void reserve(std::size_t n) {
    if (n <= capacity_) return;
    std::unique_ptr<std::byte[]> bigger(new std::byte[n]);  // default-init: no zero fill
    if (size_ > 0) std::memcpy(bigger.get(), data_.get(), size_);
    data_ = std::move(bigger);
    capacity_ = n;
  }
  /// Sets the size without initialising new bytes (caller writes them).
  void resize_uninitialized(std::size_t n) {
    if (n > capacity_) reserve(grown(n));
    size_ = n;
  }
  void append(const void* bytes, std::size_t n) {
    if (n == 0) return;
    if (size_ + n > capacity_) reserve(grown(size_ + n));
    std::memcpy(data_.get() + size_, bytes, n);
    size_ += n;
  }
  void append(std::span<const std::byte> bytes) { append(bytes.data(), bytes.size()); }

 private:
  std::size_t grown(std::size_t needed) const {
    std::size_t n = capacity_ < 4096 ? 4096 : capacity_;
    while (n < needed) n += n / 2 + 1;
    return n;
  }
  std::unique_ptr<std::byte[]> data_;
  std::size_t size_ = 0;
  std::size_t capacity_ = 0;
};

}  // namespace avs::mcap::detail
