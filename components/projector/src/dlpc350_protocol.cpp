// The DLPC350 HID framing and status words (dlpc350_protocol.hpp has the layout).
#include "avs/projector/dlpc350_protocol.hpp"

#include <algorithm>
#include <cstdio>
#include <stdexcept>

namespace avs::projector {

namespace {

constexpr std::uint8_t kFlagRead = 0x80;
constexpr std::uint8_t kFlagReply = 0x40;
constexpr std::uint8_t kFlagNack = 0x20;
constexpr std::uint8_t kDestinationMask = 0x07;
constexpr std::size_t kFirstPayloadBytes = kReportBytes - kHeaderBytes;
/// The longest message avs sends or accepts: TI's host code sizes its message buffer to 512
/// bytes (a full 128-entry pattern LUT is 2 + 384).
constexpr std::size_t kMaxPayloadBytes = 512;

std::size_t payload_length(const Report& r) {
  return static_cast<std::size_t>(r[2]) | static_cast<std::size_t>(r[3]) << 8;
}

struct Bit {
  std::uint8_t mask;
  const char* set;
  const char* clear;  ///< nullptr: say nothing when clear
};

std::vector<std::string> words_of(std::uint8_t bits, std::initializer_list<Bit> table) {
  std::vector<std::string> words;
  for (const Bit& b : table) {
    if ((bits & b.mask) != 0) {
      words.emplace_back(b.set);
    } else if (b.clear != nullptr) {
      words.emplace_back(b.clear);
    }
  }
  return words;
}

}  // namespace

std::string hex(std::uint8_t b) {
  char text[8];
  std::snprintf(text, sizeof text, "0x%02X", b);
  return text;
}

const char* command_name(Command command) {
  switch (command) {
    case Command::kVersion:
      return "GET_VERSION";
    case Command::kHardwareStatus:
      return "STATUS_HW";
    case Command::kSystemStatus:
      return "STATUS_SYS";
    case Command::kMainStatus:
      return "STATUS_MAIN";
    case Command::kValidate:
      return "LUT_VALID";
    case Command::kDisplayMode:
      return "DISP_MODE";
    case Command::kTriggerOut1:
      return "TRIG_OUT1_CTL";
    case Command::kTriggerOut2:
      return "TRIG_OUT2_CTL";
    case Command::kPatternSource:
      return "PAT_DISP_MODE";
    case Command::kPatternTriggerMode:
      return "PAT_TRIG_MODE";
    case Command::kPatternStartStop:
      return "PAT_START_STOP";
    case Command::kExposureFramePeriod:
      return "PAT_EXPO_PRD";
    case Command::kPatternConfig:
      return "PAT_CONFIG";
    case Command::kMailboxAddress:
      return "MBOX_ADDRESS";
    case Command::kMailboxControl:
      return "MBOX_CONTROL";
    case Command::kMailboxData:
      return "MBOX_DATA";
  }
  return "unknown command";
}

std::vector<Report> encode(const Request& request) {
  const std::size_t length = 2 + request.data.size();
  if (length > kMaxPayloadBytes) {
    throw std::length_error(std::string("DLPC350 ") + command_name(request.command) + ": " +
                            std::to_string(length) + " payload bytes, the controller takes " +
                            std::to_string(kMaxPayloadBytes));
  }
  std::vector<std::uint8_t> payload;
  payload.reserve(length);
  const auto code = static_cast<std::uint16_t>(request.command);
  payload.push_back(static_cast<std::uint8_t>(code & 0xFF));  // CMD3
  payload.push_back(static_cast<std::uint8_t>(code >> 8));    // CMD2
  payload.insert(payload.end(), request.data.begin(), request.data.end());

  std::vector<Report> reports(1);
  Report& first = reports[0];
  first.fill(0);
  first[0] = static_cast<std::uint8_t>((request.access == Access::kRead ? kFlagRead : 0) |
                                       (request.reply_wanted ? kFlagReply : 0));
  first[1] = request.sequence;
  first[2] = static_cast<std::uint8_t>(length & 0xFF);
  first[3] = static_cast<std::uint8_t>(length >> 8);
  std::size_t sent = std::min(length, kFirstPayloadBytes);
  std::copy_n(payload.begin(), sent, first.begin() + kHeaderBytes);
  while (sent < length) {
    Report& next = reports.emplace_back();
    next.fill(0);
    const std::size_t n = std::min(length - sent, kReportBytes);
    std::copy_n(payload.begin() + static_cast<std::ptrdiff_t>(sent), n, next.begin());
    sent += n;
  }
  return reports;
}

std::size_t request_report_count(const Report& first) {
  const std::size_t length = payload_length(first);
  if (length < 2 || length > kMaxPayloadBytes) return 0;
  if (length <= kFirstPayloadBytes) return 1;
  return 1 + (length - kFirstPayloadBytes + kReportBytes - 1) / kReportBytes;
}

DecodedRequest decode_request(const std::vector<Report>& reports) {
  if (reports.empty()) return {std::nullopt, "no report"};
  const Report& first = reports[0];
  if ((first[0] & kFlagNack) != 0 || (first[0] & kDestinationMask) != 0) {
    return {std::nullopt, "flags " + hex(first[0]) + ": not a request to the control endpoint"};
  }
  const std::size_t count = request_report_count(first);
  if (count == 0) {
    return {std::nullopt, "payload length " + std::to_string(payload_length(first)) +
                              " (bytes 2-3) is not 2.." + std::to_string(kMaxPayloadBytes)};
  }
  if (reports.size() != count) {
    return {std::nullopt, "payload length " + std::to_string(payload_length(first)) + " needs " +
                              std::to_string(count) + " reports, got " +
                              std::to_string(reports.size())};
  }
  std::vector<std::uint8_t> payload(first.begin() + kHeaderBytes, first.end());
  for (std::size_t i = 1; i < reports.size(); ++i) {
    payload.insert(payload.end(), reports[i].begin(), reports[i].end());
  }
  payload.resize(payload_length(first));
  Request r;
  r.access = (first[0] & kFlagRead) != 0 ? Access::kRead : Access::kWrite;
  r.reply_wanted = (first[0] & kFlagReply) != 0;
  r.sequence = first[1];
  r.command = static_cast<Command>(payload[0] | payload[1] << 8);
  r.data.assign(payload.begin() + 2, payload.end());
  return {r, ""};
}

Report encode_reply(const Reply& reply) {
  Report r{};
  r[0] = static_cast<std::uint8_t>(kFlagReply | (reply.nack ? kFlagNack : 0));
  r[1] = reply.sequence;
  const std::size_t n = std::min(reply.data.size(), kFirstPayloadBytes);
  r[2] = static_cast<std::uint8_t>(n & 0xFF);
  r[3] = static_cast<std::uint8_t>(n >> 8);
  std::copy_n(reply.data.begin(), n, r.begin() + kHeaderBytes);
  return r;
}

DecodedReply decode_reply(const Report& report) {
  if ((report[0] & kFlagReply) == 0 || (report[0] & kDestinationMask) != 0) {
    return {std::nullopt, "flags " + hex(report[0]) +
                              " (byte 0): not a reply (bit 6 clear) from "
                              "the control endpoint"};
  }
  const std::size_t length = payload_length(report);
  if (length > kFirstPayloadBytes) {
    return {std::nullopt, "reply length " + std::to_string(length) +
                              " (bytes 2-3) is more than one report carries (" +
                              std::to_string(kFirstPayloadBytes) + ")"};
  }
  Reply r;
  r.nack = (report[0] & kFlagNack) != 0;
  r.sequence = report[1];
  r.data.assign(report.begin() + kHeaderBytes,
                report.begin() + static_cast<std::ptrdiff_t>(kHeaderBytes + length));
  return {r, ""};
}

std::vector<std::string> hardware_status_words(std::uint8_t bits) {
  return words_of(
      bits, {{0x01, "internal initialisation: done", "internal initialisation: NOT done (error)"},
             {0x02, "incompatible controller or DMD", nullptr},
             {0x04,
              "DMD reset controller error (overlapping bias or reset "
              "operations on one DMD block)",
              nullptr},
             {0x08, "forced swap error", nullptr},
             {0x40, "sequencer abort (the sequencer stopped on an error)", nullptr},
             {0x80, "sequencer error", nullptr}});
}

bool hardware_status_ok(std::uint8_t bits) {
  return (bits & 0xCF) == 0x01;
}

std::vector<std::string> system_status_words(std::uint8_t bits) {
  return words_of(bits, {{0x01, "internal memory test: passed", "internal memory test: FAILED"}});
}

std::vector<std::string> main_status_words(std::uint8_t bits) {
  return words_of(bits, {{0x01, "DMD parked", nullptr},
                         {0x02, "sequencer running", "sequencer stopped"},
                         {0x04, "video frozen", nullptr},
                         {0x08, "external video source locked", nullptr},
                         {0x10, "port 1 syncs valid", nullptr},
                         {0x20, "port 2 syncs valid", nullptr}});
}

std::vector<std::string> validation_words(Validation v) {
  std::vector<std::string> words =
      words_of(v.bits, {{0x01, "exposure or frame period settings invalid", nullptr},
                        {0x02, "pattern numbers in the LUT invalid", nullptr},
                        {0x04,
                         "warning: continuous trigger out 1 request or overlapping black "
                         "sectors",
                         nullptr},
                        {0x08,
                         "warning: post vector not inserted before an externally "
                         "triggered vector",
                         nullptr},
                        {0x10, "warning: frame period - exposure is less than 230 us", nullptr},
                        {0x80, "busy validating", nullptr}});
  if (words.empty()) words.emplace_back("valid");
  return words;
}

std::string join_words(const std::vector<std::string>& words) {
  std::string out;
  for (const std::string& w : words) {
    if (!out.empty()) out += ", ";
    out += w;
  }
  return out;
}

}  // namespace avs::projector
