// hidapi (hidraw backend) as a HidTransport. NOT exercised by avs's tests: no LightCrafter is
// attached to the test machine (docs/devices.md section 7); the protocol above it is tested
// against the emulator. hidapi's write takes the report id (0: the DLPC350 uses none) first.
#include "avs/projector/hidapi_transport.hpp"

#include <hidapi/hidapi.h>

#include <cstdio>
#include <memory>

namespace avs::projector {

namespace {

/// hid_init() / hid_exit() around every user of the library.
class HidLibrary {
 public:
  HidLibrary() : ok_(hid_init() == 0) {}
  ~HidLibrary() { hid_exit(); }
  HidLibrary(const HidLibrary&) = delete;
  HidLibrary& operator=(const HidLibrary&) = delete;
  bool ok() const { return ok_; }

 private:
  bool ok_;
};

std::string narrow(const wchar_t* w) {
  std::string s;
  for (; w != nullptr && *w != 0; ++w) s.push_back(*w < 128 ? static_cast<char>(*w) : '?');
  return s;
}

std::string ids(std::uint16_t vid, std::uint16_t pid) {
  char text[16];
  std::snprintf(text, sizeof text, "%04x:%04x", vid, pid);
  return text;
}

class HidapiTransport final : public HidTransport {
 public:
  HidapiTransport(std::shared_ptr<HidLibrary> library, hid_device* device, std::string description)
      : library_(std::move(library)), device_(device), description_(std::move(description)) {}
  ~HidapiTransport() override { hid_close(device_); }
  HidapiTransport(const HidapiTransport&) = delete;
  HidapiTransport& operator=(const HidapiTransport&) = delete;

  IoResult write(const Report& report) override {
    unsigned char buffer[kReportBytes + 1];
    buffer[0] = 0;  // report id
    std::copy(report.begin(), report.end(), buffer + 1);
    return hid_write(device_, buffer, sizeof buffer) < 0 ? IoResult::kDisconnected : IoResult::kOk;
  }

  IoResult read(Report& report, std::chrono::milliseconds timeout) override {
    const int n =
        hid_read_timeout(device_, report.data(), report.size(), static_cast<int>(timeout.count()));
    if (n < 0) return IoResult::kDisconnected;
    if (n == 0) return IoResult::kTimeout;
    std::fill(report.begin() + n, report.end(), std::uint8_t{0});
    return IoResult::kOk;
  }

  std::string description() const override { return description_; }

 private:
  std::shared_ptr<HidLibrary> library_;
  hid_device* device_;
  std::string description_;
};

}  // namespace

bool hidapi_available() {
  return true;
}

TransportOpener hidapi_opener(HidDeviceSelector selector) {
  auto library = std::make_shared<HidLibrary>();
  return [library, selector](std::string& why_not) -> std::unique_ptr<HidTransport> {
    if (!library->ok()) {
      why_not = "hid_init() failed";
      return nullptr;
    }
    const std::string wanted = ids(selector.vendor_id, selector.product_id);
    hid_device_info* list = hid_enumerate(selector.vendor_id, selector.product_id);
    std::string path;
    std::string serial;
    std::string seen;
    for (hid_device_info* d = list; d != nullptr; d = d->next) {
      const std::string s = narrow(d->serial_number);
      seen += (seen.empty() ? "" : ", ") + std::string(d->path) + " serial '" + s + "'";
      if (path.empty() && (selector.serial.empty() || s == selector.serial)) {
        path = d->path;
        serial = s;
      }
    }
    hid_free_enumeration(list);
    if (path.empty()) {
      why_not = seen.empty()
                    ? "no USB HID device " + wanted +
                          " (LightCrafter 4500 powered and on USB? read/write access "
                          "to /dev/hidraw*: a udev rule, docs/devices.md)"
                    : "no " + wanted + " with serial '" + selector.serial + "'; found: " + seen;
      return nullptr;
    }
    hid_device* device = hid_open_path(path.c_str());
    if (device == nullptr) {
      why_not = "cannot open " + path + " (" + wanted + "): permission (udev rule) or in use";
      return nullptr;
    }
    return std::make_unique<HidapiTransport>(
        library, device, "hidapi " + wanted + " " + path + " serial '" + serial + "'");
  };
}

}  // namespace avs::projector
