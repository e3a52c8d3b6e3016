// libFuzzer target: the projector's protocol layer, the DLPC350 over USB HID, from the host's
// side. A fake transport answers the `projector` component's ProjectorLink with whatever the
// input says: reply reports of any bytes (wrong flags, sequence numbers, lengths past the
// report, NACKs, too few data bytes), timeouts, a device gone in the middle of a write or a
// read, an open that fails. The link must turn every one of these into a state and a log
// line (Dlpc350Error caught inside it): no other exception, no crash, no undefined behaviour,
// and its state and counters must agree. The controller side's parser (decode_request, as the
// emulator reads a host's reports) gets the same bytes.
// The input, read as the link calls: a byte per link step (time advanced), per open (device
// there or not), per report written (ok, timeout, gone) and per report read (an answer to the
// last request with its data bytes from the input, with another sequence number, a NACK, a
// report of the next 64 input bytes, a timeout, gone). Zero bytes are the happy path: the
// link opens, configures, starts and polls the status.
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "avs/projector/dlpc350_protocol.hpp"
#include "avs/projector/hid_transport.hpp"
#include "avs/projector/projector_link.hpp"

namespace {

using namespace avs::projector;

[[noreturn]] void fail(const std::string& what) {
  std::fprintf(stderr, "projector_link_fuzz: %s\n", what.c_str());
  std::abort();
}

/// The input, read from the front; empty input reads as zeros.
class Input {
 public:
  explicit Input(std::span<const std::uint8_t> bytes) : bytes_(bytes) {}
  bool empty() const { return at_ >= bytes_.size(); }
  std::uint8_t byte() { return empty() ? 0 : bytes_[at_++]; }
  Report report() {
    Report r{};
    for (auto& b : r) b = byte();
    return r;
  }

 private:
  std::span<const std::uint8_t> bytes_;
  std::size_t at_ = 0;
};

/// A device that answers as the input says. Replies it makes itself echo the last request's
/// sequence number with plausible data, so that the link gets past the first read to the
/// configuration and the status polls, where the input's own reports then land.
class FuzzTransport final : public HidTransport {
 public:
  explicit FuzzTransport(Input& in) : in_(in) {}

  IoResult write(const Report& report) override {
    if (in_.empty()) return IoResult::kDisconnected;
    const std::uint8_t what = in_.byte();
    if (what >> 6 == 3) return (what & 1) != 0 ? IoResult::kTimeout : IoResult::kDisconnected;
    // The first report of a request has the header; its continuations carry none.
    if (pending_reports_ == 0) {
      pending_reports_ = request_report_count(report);
      if (pending_reports_ == 0) fail("the client wrote a report no request can start with");
      request_reports_.clear();
      last_request_ = report;
    }
    request_reports_.push_back(report);
    // What the controller reads (the emulator's parser) must accept the client's request.
    if (--pending_reports_ == 0 && !decode_request(request_reports_).request) {
      fail("the client's request does not decode: " + decode_request(request_reports_).error);
    }
    return IoResult::kOk;
  }

  IoResult read(Report& report, std::chrono::milliseconds) override {
    if (in_.empty()) return IoResult::kDisconnected;
    const std::uint8_t what = in_.byte();
    switch (what >> 5) {
      case 4:
        report = in_.report();  // anything at all
        return IoResult::kOk;
      case 6:
        return IoResult::kTimeout;
      case 7:
        return IoResult::kDisconnected;
      default: {  // 0-3, 5: an answer to the last request (5: NACK), its data from the input
        Reply reply;
        reply.sequence = static_cast<std::uint8_t>(last_request_[1] + ((what & 0x08) != 0 ? 1 : 0));
        reply.nack = what >> 5 == 5;
        const std::size_t bytes = (what & 0x07) == 7 ? 0 : 1 + (what & 0x07);
        for (std::size_t k = 0; k < bytes; ++k) reply.data.push_back(in_.byte());
        report = encode_reply(reply);
        return IoResult::kOk;
      }
    }
  }

  std::string description() const override { return "fuzz transport"; }

 private:
  Input& in_;
  Report last_request_{};
  std::vector<Report> request_reports_;
  std::size_t pending_reports_ = 0;  ///< reports of the request being written still to come
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  // The controller's side parses the same bytes as a host's request reports.
  {
    std::vector<Report> reports;
    for (std::size_t at = 0; at + kReportBytes <= size && reports.size() < 4; at += kReportBytes) {
      Report r{};
      for (std::size_t k = 0; k < kReportBytes; ++k) r[k] = data[at + k];
      reports.push_back(r);
    }
    if (!reports.empty()) {
      (void)request_report_count(reports.front());
      const DecodedRequest request = decode_request(reports);
      if (!request.request && request.error.empty()) fail("a request refused without a reason");
      (void)decode_reply(reports.front());
    }
  }

  Input in({data, size});
  LinkConfig config;
  config.timeouts_before_lost = 1 + in.byte() % 3;
  config.max_validate_polls = 1 + in.byte() % 4;
  config.match_reply_sequence = (in.byte() & 1) != 0;
  int opens = 0;
  ProjectorLink link(config, [&](std::string& why_not) -> std::unique_ptr<HidTransport> {
    ++opens;
    if (in.byte() >> 6 == 3) {
      why_not = "the input said no device";
      return nullptr;
    }
    return std::make_unique<FuzzTransport>(in);
  });
  auto now = std::chrono::steady_clock::time_point{};
  for (int step = 0; step < 64 && !in.empty(); ++step) {
    now += std::chrono::milliseconds(100 * (1 + in.byte() % 16));
    const std::vector<LinkEvent> events = link.step(now);
    for (const LinkEvent& e : events) {
      if (e.text.empty()) fail("an empty log line");
    }
    const LinkCounters& c = link.counters();
    if (c.connects > static_cast<std::uint64_t>(opens)) fail("more connects than opens");
    if (link.state() == LinkState::kRunning && c.connects == 0) fail("running, never connected");
    if (c.disconnects > c.connects) fail("more disconnects than connects");
  }
  (void)link.close();
  if (link.state() != LinkState::kDisconnected) fail("still connected after close");
  return 0;
}
