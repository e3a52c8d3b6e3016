// SimGigECamera: Aravis's GV fake camera with our frames, see the header.
#include "sim_gige_camera.hpp"

#include <arv.h>

#include <algorithm>
#include <cstring>
#include <stdexcept>

#include "glib_handles.hpp"

namespace avs::camera {

struct SimGigECamera::Impl {
  detail::GObjectPtr<ArvGvFakeCamera> fake;
};

SimGigECamera::SimGigECamera(SimGigECameraConfig config, int width, int height, Render render)
    : config_(std::move(config)),
      width_(width),
      height_(height),
      render_(std::move(render)),
      impl_(std::make_unique<Impl>()) {
  impl_->fake.reset(
      arv_gv_fake_camera_new_full(config_.interface.c_str(), config_.serial.c_str(), nullptr));
  if (impl_->fake == nullptr || !arv_gv_fake_camera_is_running(impl_->fake.get())) {
    throw std::runtime_error("sim camera: cannot serve a GigE Vision camera on '" +
                             config_.interface +
                             "' (GVCP port 3956): no such interface, or the port is taken by "
                             "another (fake) camera");
  }
  if (config_.lost_packet_ratio > 0) {
    // GvFakeCamera's "gvsp-lost-packet-ratio" property came after Aravis 0.8.26 (Debian 12).
    if (g_object_class_find_property(G_OBJECT_GET_CLASS(impl_->fake.get()),
                                     "gvsp-lost-packet-ratio") == nullptr) {
      throw std::runtime_error(
          "sim camera: lost_packet_ratio " + std::to_string(config_.lost_packet_ratio) +
          " needs the GV fake camera's gvsp-lost-packet-ratio property, which this Aravis (" +
          std::to_string(arv_get_major_version()) + "." + std::to_string(arv_get_minor_version()) +
          "." + std::to_string(arv_get_micro_version()) + ") does not have; use drop_frames");
    }
    g_object_set(impl_->fake.get(), "gvsp-lost-packet-ratio", config_.lost_packet_ratio, nullptr);
  }
  ArvFakeCamera* camera = arv_gv_fake_camera_get_fake_camera(impl_->fake.get());
  arv_fake_camera_set_trigger_frequency(camera, config_.frame_rate_hz);
  arv_fake_camera_set_fill_pattern(
      camera,
      [](ArvBuffer* buffer, void* self, guint32, guint32, ArvPixelFormat format) {
        static_cast<SimGigECamera*>(self)->fill(buffer, format == ARV_PIXEL_FORMAT_MONO_8);
      },
      this);
}

SimGigECamera::~SimGigECamera() {
  // No more callbacks into this object, then the fake camera's thread stops.
  arv_fake_camera_set_fill_pattern(arv_gv_fake_camera_get_fake_camera(impl_->fake.get()), nullptr,
                                   nullptr);
  impl_.reset();
}

void SimGigECamera::fill(void* raw_buffer, bool mono8) {
  auto* buffer = static_cast<ArvBuffer*>(raw_buffer);
  std::uint64_t k = next_++;
  while (config_.drop_frames.contains(k)) {
    k = next_++;
    ++skipped_;
  }
  const int width = arv_buffer_get_image_width(buffer);
  const int height = arv_buffer_get_image_height(buffer);
  size_t size = 0;
  auto* data = static_cast<std::uint8_t*>(const_cast<void*>(arv_buffer_get_data(buffer, &size)));
  const std::size_t pixels = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
  if (!mono8 || width != width_ || height != height_ || data == nullptr) {
    ++mismatched_;
    if (data != nullptr) std::memset(data, 0, std::min<std::size_t>(size, pixels));
  } else {
    render_(k, data);
  }
  // GigE Vision block ids: 16 bits, 0 skipped.
  arv_buffer_set_frame_id(buffer, (config_.first_frame_id - 1 + k) % 65535 + 1);
  const auto period_ns = static_cast<std::uint64_t>(1e9 / config_.frame_rate_hz);
  arv_buffer_set_timestamp(buffer, config_.host_timestamps
                                       ? static_cast<std::uint64_t>(g_get_real_time()) * 1000
                                       : (k + 1) * period_ns);
  ++filled_;
}

}  // namespace avs::camera
