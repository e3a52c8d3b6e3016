// The DLPC350's USB HID command protocol (DLP LightCrafter 4500; TI DLPC350 programmer's
// guide, "USB interface" and "pattern display commands"), with no I/O: requests encoded into
// 64-byte HID reports and replies decoded from them, byte for byte, and the controller's status
// and validation bits decoded into words. docs/devices.md section 7 shows the layout.
//
// A message is a 4-byte header then its payload:
//   byte 0  flags: bit 7 read (1) / write (0), bit 6 reply wanted, bit 5 NACK (replies),
//           bits 2..0 destination (0: the projector control endpoint)
//   byte 1  sequence number (echoed in the reply)
//   byte 2-3 payload length, little-endian (requests: the two command bytes + data)
//   then    requests: CMD3, CMD2 (the 16-bit command code CMD2 << 8 | CMD3, little-endian),
//           then the data; replies: the data only.
// A payload longer than one report continues in the next reports, 64 data bytes each, with no
// header. hidapi's write takes one more leading byte, the report id (0); the transport adds it.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace avs::projector {

/// One HID report as the controller sends and receives it (without hidapi's report id byte).
constexpr std::size_t kReportBytes = 64;
using Report = std::array<std::uint8_t, kReportBytes>;
constexpr std::size_t kHeaderBytes = 4;

/// TI's USB ids of the LightCrafter 4500 (the DLPC350 enumerates as a HID device).
constexpr std::uint16_t kUsbVendorId = 0x0451;
constexpr std::uint16_t kUsbProductId = 0x6401;

/// Command codes (CMD2 << 8 | CMD3) of the programmer's guide that avs uses.
enum class Command : std::uint16_t {
  kVersion = 0x0205,              ///< read: application, API, SW and sequence config versions
  kHardwareStatus = 0x1A0A,       ///< read: 1 byte (hardware_status_words)
  kSystemStatus = 0x1A0B,         ///< read: 1 byte (system_status_words)
  kMainStatus = 0x1A0C,           ///< read: 1 byte (main_status_words)
  kValidate = 0x1A1A,             ///< write 1 byte: validate; read: the validation bits
  kDisplayMode = 0x1A1B,          ///< 1 byte: 0 video mode, 1 pattern sequence mode
  kTriggerOut1 = 0x1A1D,          ///< 3 bytes: invert, rising delay, falling delay
  kTriggerOut2 = 0x1A1E,          ///< 2 bytes: invert, rising delay
  kPatternSource = 0x1A22,        ///< 1 byte: 0 video port, 3 internal flash
  kPatternTriggerMode = 0x1A23,   ///< 1 byte: 0 VSYNC, 1 internal / external trigger, ...
  kPatternStartStop = 0x1A24,     ///< 1 byte: 0 stop, 1 pause, 2 start
  kExposureFramePeriod = 0x1A29,  ///< 8 bytes: exposure us, frame period us (uint32 LE)
  kPatternConfig = 0x1A31,        ///< 4 bytes: LUT entries - 1, repeat, trig-out-2 pats - 1,
                                  ///< image LUT entries - 1
  kMailboxAddress = 0x1A32,       ///< 1 byte: offset in the open mailbox
  kMailboxControl = 0x1A33,       ///< 1 byte: 0 close, 1 image LUT, 2 pattern LUT
  kMailboxData = 0x1A34,          ///< n bytes: entries at the mailbox address
};

/// "0x1F": a byte for messages.
std::string hex(std::uint8_t b);

/// "PAT_START_STOP" etc.: the programmer's guide's name of a command, for messages.
const char* command_name(Command command);

enum class Access : std::uint8_t { kWrite, kRead };

/// A request to the controller: a write (data = the command's parameters) or a read.
struct Request {
  Command command = Command::kMainStatus;
  Access access = Access::kWrite;
  bool reply_wanted = true;  ///< writes: the controller answers with an ACK or NACK report
  std::uint8_t sequence = 0;
  std::vector<std::uint8_t> data;
};

/// The reports that carry `request`: the first with the header, then continuations.
std::vector<Report> encode(const Request& request);

/// A reply report decoded. Replies avs reads fit one report (at most 60 data bytes).
struct Reply {
  bool nack = false;  ///< the controller refused the command (unknown, bad parameter, ...)
  std::uint8_t sequence = 0;
  std::vector<std::uint8_t> data;
};

/// Decodes a reply report, or says why it is not one (a request's flags, a length past the
/// report): the error names the bytes.
struct DecodedReply {
  std::optional<Reply> reply;
  std::string error;
};
DecodedReply decode_reply(const Report& report);

/// Decodes a request from its reports as the controller does (the emulator; tests).
/// `reports` holds the first report and its continuations.
struct DecodedRequest {
  std::optional<Request> request;
  std::string error;
};
DecodedRequest decode_request(const std::vector<Report>& reports);

/// How many reports a request whose first report is `first` spans (1 + continuations); 0 if
/// `first` has a length no request can have.
std::size_t request_report_count(const Report& first);

/// The reply report the controller sends (the emulator).
Report encode_reply(const Reply& reply);

// ---- Status bits (programmer's guide, "DLPC350 status commands") ----

/// Words for the set bits that matter, e.g. {"internal initialisation: done",
/// "sequencer error"}; an empty list never (initialisation is always reported).
std::vector<std::string> hardware_status_words(std::uint8_t bits);
std::vector<std::string> system_status_words(std::uint8_t bits);
std::vector<std::string> main_status_words(std::uint8_t bits);

/// Hardware status faults: initialisation not done, incompatible controller or DMD, DMD reset
/// controller error, forced swap error, sequencer abort, sequencer error.
bool hardware_status_ok(std::uint8_t bits);
constexpr std::uint8_t kMainSequencerRunning = 0x02;

/// The validation bits (read of kValidate): bit 7 busy, bits 0-1 errors, bits 2-4 warnings.
struct Validation {
  std::uint8_t bits = 0;
  bool busy() const { return (bits & 0x80) != 0; }
  /// No error bit (0, 1): the controller will run the sequence.
  bool valid() const { return (bits & 0x03) == 0; }
  /// No warning either (bits 2-4): what avs asks for.
  bool clean() const { return (bits & 0x1F) == 0; }
};
std::vector<std::string> validation_words(Validation v);

/// "a, b, c" (for one log line).
std::string join_words(const std::vector<std::string>& words);

}  // namespace avs::projector
