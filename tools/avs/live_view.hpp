// `--view` of the commands that run or replay a graph (`avs demo`, `avs bag play`): the live
// view (libs/view, the same server as `avs view`) started in the command's own process, on
// the DDS domain and partition it publishes to, with its address printed. One place for the
// flags, their help and the start-up line.
#pragma once

#include <memory>
#include <ostream>
#include <string>

#include "avs/view/view.hpp"
#include "command.hpp"

namespace avs::cli {

struct LiveViewFlags {
  bool enabled = false;
  unsigned port = 8765;  ///< Foxglove's default; 0: any free port
};

/// Adds --view and --view-port to `cmd`; `what` names what is served ("the run", "the bag").
void add_live_view_options(Command* cmd, LiveViewFlags& flags, const std::string& what);

/// The started server when flags.enabled, else nullptr. Prints "<who>: live view at
/// http://127.0.0.1:PORT/?PAGE_QUERY (Foxglove: ws://127.0.0.1:PORT)" to `out`; page_query
/// is e.g. "object=ken" (the page's options, docs/view.md), empty for none. Throws
/// runtime::Error for a port out of range or one that cannot be opened.
std::unique_ptr<view::View> start_live_view(const LiveViewFlags& flags, int domain,
                                            const std::string& partition, const std::string& who,
                                            std::ostream& out, const std::string& page_query = "");

}  // namespace avs::cli
