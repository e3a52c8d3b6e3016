// libFuzzer target for the MCAP reader: any input must give an error or success, never a
// crash, leak or out-of-bounds access (built with -fsanitize=fuzzer,address,undefined).
// Run: tools/fuzz.sh, or fuzz_mcap_reader -max_total_time=60 NEW_DIR tests/mcap/data
#include <cstddef>
#include <cstdint>
#include <span>

#include "avs/mcap/reader.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace avs::mcap;
  ReaderOptions limits;
  limits.max_chunk_uncompressed_bytes = 16u << 20;
  const auto bytes = std::as_bytes(std::span(data, size));
  for (int pass = 0; pass < 3; ++pass) {
    // Strict, tolerating truncation, and skipping corrupt chunks as `bag play` and `bag repair`
    // do (the resynchronisation after a lost record framing).
    const bool allow_truncated = pass > 0;
    limits.skip_corrupt_chunks = pass == 2;
    Reader reader;
    if (!reader.open_memory(bytes, limits).ok()) return 0;
    ReadOptions options;
    options.allow_truncated = allow_truncated;
    std::uint64_t checksum = 0;
    (void)reader.read_messages(
        [&](const MessageView& view) {
          checksum += view.log_time + view.data.size() + view.channel->topic.size();
          if (!view.data.empty()) checksum += static_cast<std::uint8_t>(view.data.back());
          return true;
        },
        options);
    ScanResult scanned;
    (void)reader.scan(scanned, allow_truncated);
    if (checksum == 1) return 0;  // keeps the reads observable
  }
  return 0;
}
