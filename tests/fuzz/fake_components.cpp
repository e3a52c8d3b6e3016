#include "fake_components.hpp"

#include <memory>

#include "avs/msg/type_support.hpp"
#include "avs/runtime/component.hpp"

namespace avs::fuzz {

void register_fake_components() {
  static const bool done = [] {
    using runtime::ParamSpec;
    auto& registry = runtime::ComponentRegistry::instance();
    auto factory = [](runtime::ComponentContext& ctx) {
      return std::make_unique<runtime::Component>(ctx);
    };
    runtime::ComponentSpec talker;
    talker.type = "fake_talker";
    talker.parameters = {
        ParamSpec::real("rate_hz", 10.0, 0.1, 10000.0, "Hz", "publish rate"),
        ParamSpec::integer("count", 3, 0.0, 1000.0, "", "messages"),
        ParamSpec::boolean("enabled", true, "publish at all"),
        ParamSpec::string("mode", "fast", "speed", {"fast", "slow"}),
        ParamSpec::real_list("gains", {1.0, 2.0, 3.0}, "", "gains"),
        ParamSpec::string("label", "", "text"),
    };
    talker.publishes = {runtime::port<std_msgs_msg_dds__String_>("chatter", "chatter")};
    registry.add(talker, factory);

    runtime::ComponentSpec camera;
    camera.type = "fake_camera";
    camera.publishes = {runtime::port<sensor_msgs_msg_dds__Image_>(
        "image", "image", *runtime::QosProfile::named("sensor_data"))};
    camera.subscribes = {runtime::port<std_msgs_msg_dds__String_>("chatter", "chatter")};
    registry.add(camera, factory);
    return true;
  }();
  (void)done;
}

}  // namespace avs::fuzz
