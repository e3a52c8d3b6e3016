// The USB HID transport to a real DLPC350 through hidapi (hidraw backend), and whether this
// build has it. hidapi's headers stay in hidapi_transport.cpp.
#pragma once

#include <cstdint>
#include <string>

#include "avs/projector/hid_transport.hpp"

namespace avs::projector {

struct HidDeviceSelector {
  std::uint16_t vendor_id = kUsbVendorId;
  std::uint16_t product_id = kUsbProductId;
  std::string serial;  ///< empty: the first device with these ids
};

/// False when avs was built without hidapi (CMake said so): hidapi_opener then always fails.
bool hidapi_available();

/// Opens the selected device through hidapi; `why_not` lists what was found instead.
TransportOpener hidapi_opener(HidDeviceSelector selector);

}  // namespace avs::projector
