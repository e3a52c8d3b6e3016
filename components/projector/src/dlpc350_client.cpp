// DLPC350 requests over a HidTransport (dlpc350_client.hpp).
#include "avs/projector/dlpc350_client.hpp"

namespace avs::projector {

namespace {

using Kind = Dlpc350Error::Kind;

std::string context(const Request& r) {
  return std::string("DLPC350 ") + (r.access == Access::kRead ? "read " : "write ") +
         command_name(r.command) + " (sequence " + std::to_string(r.sequence) + ")";
}

}  // namespace

std::string DeviceStatus::words() const {
  return "hardware: " + join_words(hardware_status_words(hardware)) +
         "; system: " + join_words(system_status_words(system)) +
         "; main: " + join_words(main_status_words(main));
}

Dlpc350Client::Dlpc350Client(HidTransport& transport, std::chrono::milliseconds usb_timeout,
                             bool match_sequence, int max_stale_replies)
    : transport_(transport),
      usb_timeout_(usb_timeout),
      match_sequence_(match_sequence),
      max_stale_replies_(max_stale_replies) {}

Reply Dlpc350Client::transact(Request request) {
  request.sequence = next_sequence_++;
  request.reply_wanted = true;
  for (const Report& report : encode(request)) {
    if (const IoResult r = transport_.write(report); r != IoResult::kOk) {
      throw Dlpc350Error(r == IoResult::kDisconnected ? Kind::kDisconnected : Kind::kTimeout,
                         context(request) + ": USB write failed (" +
                             (r == IoResult::kDisconnected ? "device gone" : "timeout") + ")");
    }
  }
  // A reply with another sequence number answers an earlier request that timed out: skip it.
  for (int attempt = 0; attempt <= max_stale_replies_; ++attempt) {
    Report report{};
    const IoResult r = transport_.read(report, usb_timeout_);
    if (r == IoResult::kDisconnected) {
      throw Dlpc350Error(Kind::kDisconnected, context(request) +
                                                  ": device gone while waiting "
                                                  "for the reply");
    }
    if (r == IoResult::kTimeout) {
      throw Dlpc350Error(Kind::kTimeout, context(request) + ": no reply within " +
                                             std::to_string(usb_timeout_.count()) + " ms");
    }
    DecodedReply decoded = decode_reply(report);
    if (!decoded.reply) {
      throw Dlpc350Error(Kind::kBadReply, context(request) + ": " + decoded.error);
    }
    if (match_sequence_ && decoded.reply->sequence != request.sequence) continue;
    if (decoded.reply->nack) {
      throw Dlpc350Error(Kind::kNack, context(request) +
                                          ": the controller answered NACK "
                                          "(command refused)");
    }
    return std::move(*decoded.reply);
  }
  throw Dlpc350Error(Kind::kBadReply, context(request) + ": " +
                                          std::to_string(max_stale_replies_ + 1) +
                                          " replies, none with this sequence number (a "
                                          "controller that does not echo it: "
                                          "match_reply_sequence: false)");
}

void Dlpc350Client::write(Command command, std::vector<std::uint8_t> data) {
  Request r;
  r.command = command;
  r.access = Access::kWrite;
  r.data = std::move(data);
  (void)transact(std::move(r));
}

std::vector<std::uint8_t> Dlpc350Client::read(Command command, std::size_t min_bytes) {
  Request r;
  r.command = command;
  r.access = Access::kRead;
  Reply reply = transact(r);
  if (reply.data.size() < min_bytes) {
    throw Dlpc350Error(Kind::kBadReply, std::string("DLPC350 read ") + command_name(command) +
                                            ": " + std::to_string(reply.data.size()) +
                                            " data bytes, expected " + std::to_string(min_bytes));
  }
  return std::move(reply.data);
}

DeviceStatus Dlpc350Client::read_status() {
  DeviceStatus s;
  s.hardware = read(Command::kHardwareStatus, 1)[0];
  s.system = read(Command::kSystemStatus, 1)[0];
  s.main = read(Command::kMainStatus, 1)[0];
  return s;
}

Validation Dlpc350Client::configure(const SequenceConfig& config, int max_polls) {
  for (Request& r : configure_requests(config)) write(r.command, std::move(r.data));
  for (int poll = 0; poll < max_polls; ++poll) {
    const Validation v{read(Command::kValidate, 1)[0]};
    if (!v.busy()) return v;
  }
  throw Dlpc350Error(Kind::kTimeout, "DLPC350 LUT_VALID: still busy validating after " +
                                         std::to_string(max_polls) + " reads");
}

}  // namespace avs::projector
