// Reading /diagnostics in a test: a plain DDS reader on rt/diagnostics (another participant than
// the container's, which publishes only when a remote reader is matched).
#pragma once

#include <string_view>

#include "avs/runtime/dds.hpp"
#include "avs/runtime/sample.hpp"
#include "diagnostic_msgs.h"

namespace avs::testing {

/// Takes every DiagnosticArray `reader` holds and calls fn(status) for each DiagnosticStatus
/// named `name` ("container/component"; empty: every status), in arrival order.
template <class Fn>
void take_diagnostic_statuses(const runtime::dds::Reader& reader, std::string_view name, Fn fn) {
  using Array = msgs::diagnostic_msgs::DiagnosticArray;
  for (;;) {
    auto sample = runtime::make_sample<Array>();
    void* buffers[1] = {sample.get()};
    dds_sample_info_t info;
    if (dds_take(reader.get(), buffers, &info, 1, 1) <= 0) break;
    if (!info.valid_data) continue;
    for (const auto& status : runtime::as_span(sample->status)) {
      if (name.empty() || runtime::get_string(status.name) == name) fn(status);
    }
  }
}

}  // namespace avs::testing
