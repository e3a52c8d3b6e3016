// Status: the one error value of avs::mcap. Every I/O or parsing call returns one; a failed
// status carries a code and a message naming the file offset (or the argument) at fault.
#pragma once

#include <string>
#include <utility>

namespace avs::mcap {

enum class StatusCode {
  ok,
  invalid_argument,  ///< caller error (unknown channel id, writer not open, ...)
  io_error,          ///< open/read/write/rename failed (errno text in the message)
  malformed,         ///< bytes that break the MCAP specification
  truncated,         ///< a record or field runs past the end of the file
  crc_mismatch,      ///< a chunk, data-section or summary CRC does not match
  unsupported,       ///< valid MCAP that this library does not handle (e.g. unknown compression)
  too_large,         ///< a size above the reader's configured limits
  incomplete,        ///< repair: the result lacks part of the input, so it did not replace it
};

const char* status_code_name(StatusCode code);

class [[nodiscard]] Status {
 public:
  Status() = default;
  Status(StatusCode code, std::string message) : code_(code), message_(std::move(message)) {}

  static Status success() { return {}; }

  bool ok() const { return code_ == StatusCode::ok; }
  StatusCode code() const { return code_; }
  const std::string& message() const { return message_; }
  /// "malformed: chunk at offset 1234: ..." (or "ok").
  std::string to_string() const;

 private:
  StatusCode code_ = StatusCode::ok;
  std::string message_;
};

}  // namespace avs::mcap
