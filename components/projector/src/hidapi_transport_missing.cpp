// Built without hidapi (CMake warned): no USB transport; `transport: hid` fails with this.
#include "avs/projector/hidapi_transport.hpp"

namespace avs::projector {

bool hidapi_available() {
  return false;
}

TransportOpener hidapi_opener(HidDeviceSelector) {
  return [](std::string& why_not) -> std::unique_ptr<HidTransport> {
    why_not = "avs was built without hidapi (install libhidapi-dev and reconfigure)";
    return nullptr;
  };
}

}  // namespace avs::projector
