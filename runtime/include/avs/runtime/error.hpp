// One error type for the runtime, and the one place DDS return codes are checked.
#pragma once

#include <stdexcept>
#include <string>
#include <string_view>

#include <dds/dds.h>

namespace avs::runtime {

/// An error with the context that caused it ("create writer on rt/depth: ...").
class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Throws Error naming `what` when `rc` is a negative DDS return code; returns `rc` otherwise.
/// Every Cyclone call whose result matters goes through here.
inline dds_return_t check_dds(dds_return_t rc, std::string_view what) {
  if (rc < 0) {
    throw Error(std::string(what) + ": " + dds_strretcode(rc) + " (" + std::to_string(rc) + ")");
  }
  return rc;
}

}  // namespace avs::runtime
