// AravisCamera: Aravis 0.8 calls behind aravis_camera.hpp. Every GError is turned into one
// line naming the camera, the feature, the value and what the camera allows.
#include "aravis_camera.hpp"

#include <arv.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string_view>

#include "glib_handles.hpp"

namespace avs::camera {

using detail::ErrorSlot;
using detail::GFreePtr;
using detail::GObjectPtr;

std::vector<std::string> list_cameras() {
  arv_update_device_list();
  std::vector<std::string> out;
  const unsigned n = arv_get_n_devices();
  for (unsigned i = 0; i < n; ++i) {
    const auto text = [](const char* s) { return std::string(s != nullptr ? s : "?"); };
    out.push_back(text(arv_get_device_id(i)) + " (" + text(arv_get_device_vendor(i)) + " " +
                  text(arv_get_device_model(i)) + ", serial " + text(arv_get_device_serial_nbr(i)) +
                  ", " + text(arv_get_device_protocol(i)) + " " + text(arv_get_device_address(i)) +
                  ")");
  }
  return out;
}

namespace {

std::string joined(const std::vector<std::string>& items, std::string_view separator) {
  std::string out;
  for (const std::string& s : items) out += (out.empty() ? "" : std::string(separator)) + s;
  return out;
}

std::string number(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

/// The device to open: `wanted`, or the only camera found (errors list what was found).
std::string choose_device(const std::string& wanted, const std::vector<std::string>& found) {
  if (!wanted.empty()) return wanted;
  if (found.empty()) {
    throw std::runtime_error(
        "camera: no GenICam camera found (GigE Vision: is it on a subnet of this host's "
        "interfaces? USB3 Vision: udev permissions?); `arv-tool-0.8` lists what Aravis sees");
  }
  if (found.size() > 1) {
    throw std::runtime_error("camera: " + std::to_string(found.size()) +
                             " cameras found, set device_id to one of: " + joined(found, "; "));
  }
  return found.front().substr(0, found.front().find(" ("));
}

const char* status_text(ArvBufferStatus status) {
  switch (status) {
    case ARV_BUFFER_STATUS_SUCCESS:
      return "success";
    case ARV_BUFFER_STATUS_CLEARED:
      return "cleared";
    case ARV_BUFFER_STATUS_TIMEOUT:
      return "timeout (packets did not arrive in time)";
    case ARV_BUFFER_STATUS_MISSING_PACKETS:
      return "missing packets";
    case ARV_BUFFER_STATUS_WRONG_PACKET_ID:
      return "wrong packet id";
    case ARV_BUFFER_STATUS_SIZE_MISMATCH:
      return "size mismatch (payload larger than the buffer)";
    case ARV_BUFFER_STATUS_FILLING:
      return "still filling";
    case ARV_BUFFER_STATUS_ABORTED:
      return "aborted";
    default:
      return "unknown status";
  }
}

}  // namespace

struct AravisCamera::Impl {
  CameraConfig config;
  std::string device;
  GObjectPtr<ArvCamera> camera;
  GObjectPtr<ArvStream> stream;
  std::string description;
  bool gige = false;
  bool acquiring = false;

  std::string where() const { return "camera " + device; }

  [[noreturn]] void refuse(const std::string& feature, const std::string& value,
                           const std::string& why, const std::string& allowed) const {
    throw std::runtime_error(where() + ": " + feature + " = " + value + " " + why +
                             (allowed.empty() ? std::string() : "; the camera allows " + allowed));
  }

  /// The first of `names` the camera implements (GenICam SFNC names and their older aliases).
  std::string feature_name(std::initializer_list<const char*> names) const {
    for (const char* name : names) {
      ErrorSlot e;
      if (arv_camera_is_feature_available(camera.get(), name, e.out()) && !e.failed()) return name;
    }
    return {};
  }

  std::string enumeration_entries(const std::string& feature) const {
    ErrorSlot e;
    guint n = 0;
    GFreePtr<const char*> entries(arv_camera_dup_available_enumerations_as_strings(
        camera.get(), feature.c_str(), &n, e.out()));
    std::vector<std::string> names;
    for (guint i = 0; entries && i < n; ++i) names.emplace_back(entries.get()[i]);
    return names.empty() ? std::string("(none listed)") : joined(names, ", ");
  }

  void set_enumeration(const std::string& feature, const std::string& value) {
    if (feature_name({feature.c_str()}).empty()) {
      refuse(feature, value, "cannot be set: the camera has no such feature", "");
    }
    ErrorSlot e;
    arv_camera_set_string(camera.get(), feature.c_str(), value.c_str(), e.out());
    if (e.failed())
      refuse(feature, value, "rejected (" + e.message() + ")", enumeration_entries(feature));
    const char* now = arv_camera_get_string(camera.get(), feature.c_str(), e.out());
    if (e.failed() || now == nullptr || value != now) {
      refuse(feature, value, "did not stick (reads back " + std::string(now ? now : "?") + ")",
             enumeration_entries(feature));
    }
  }

  void set_integer(const std::string& feature, std::int64_t value) {
    if (feature_name({feature.c_str()}).empty()) {
      refuse(feature, std::to_string(value), "cannot be set: the camera has no such feature", "");
    }
    ErrorSlot e;
    gint64 min = 0, max = 0;
    arv_camera_get_integer_bounds(camera.get(), feature.c_str(), &min, &max, e.out());
    const gint64 increment = std::max<gint64>(
        1, arv_camera_get_integer_increment(camera.get(), feature.c_str(), nullptr));
    const std::string allowed = std::to_string(min) + ".." + std::to_string(max) +
                                (increment > 1 ? " in steps of " + std::to_string(increment) : "");
    if (!e.failed() && (value < min || value > max || (value - min) % increment != 0)) {
      refuse(feature, std::to_string(value), "is out of range", allowed);
    }
    arv_camera_set_integer(camera.get(), feature.c_str(), value, e.out());
    if (e.failed())
      refuse(feature, std::to_string(value), "rejected (" + e.message() + ")", allowed);
    const gint64 now = arv_camera_get_integer(camera.get(), feature.c_str(), e.out());
    if (e.failed() || now != value) {
      refuse(feature, std::to_string(value),
             "did not stick (reads back " + std::to_string(now) + ")", allowed);
    }
  }

  /// Sets the first implemented of `names` (e.g. ExposureTime, ExposureTimeAbs).
  void set_float(std::initializer_list<const char*> names, double value) {
    const std::string feature = feature_name(names);
    if (feature.empty()) {
      refuse(*names.begin(), number(value), "cannot be set: the camera has no such feature", "");
    }
    ErrorSlot e;
    double min = 0, max = 0;
    arv_camera_get_float_bounds(camera.get(), feature.c_str(), &min, &max, e.out());
    const std::string allowed = number(min) + ".." + number(max);
    if (!e.failed() && (value < min || value > max)) {
      refuse(feature, number(value), "is out of range", allowed);
    }
    arv_camera_set_float(camera.get(), feature.c_str(), value, e.out());
    if (e.failed()) refuse(feature, number(value), "rejected (" + e.message() + ")", allowed);
    const double now = arv_camera_get_float(camera.get(), feature.c_str(), e.out());
    if (e.failed() || std::abs(now - value) > 1e-3 * std::max(1.0, std::abs(value))) {
      refuse(feature, number(value), "did not stick (reads back " + number(now) + ")", allowed);
    }
  }

  /// Sets an integer feature that may be exposed as a float (Gain vs GainRaw).
  void set_gain(double value) {
    const std::string feature = feature_name({"Gain", "GainRaw", "GainAbs"});
    if (feature == "GainRaw") {
      set_integer(feature, std::llround(value));
    } else {
      set_float({"Gain", "GainAbs"}, value);
    }
  }

  void configure_region() {
    const CameraConfig& c = config;
    gint sensor_width = 0, sensor_height = 0;
    ErrorSlot e;
    arv_camera_get_sensor_size(camera.get(), &sensor_width, &sensor_height, e.out());
    e.clear();
    // Offsets to 0 first so that the full width and height are allowed.
    if (!feature_name({"OffsetX"}).empty()) set_integer("OffsetX", 0);
    if (!feature_name({"OffsetY"}).empty()) set_integer("OffsetY", 0);
    set_integer("Width", c.width);
    set_integer("Height", c.height);
    const auto centred = [&](int sensor, int size, const char* feature) -> std::int64_t {
      const gint64 inc =
          std::max<gint64>(1, arv_camera_get_integer_increment(camera.get(), feature, nullptr));
      const std::int64_t offset = std::max(0, (sensor - size) / 2);
      return offset / inc * inc;
    };
    const std::int64_t x = c.offset_x >= 0 ? c.offset_x : centred(sensor_width, c.width, "OffsetX");
    const std::int64_t y =
        c.offset_y >= 0 ? c.offset_y : centred(sensor_height, c.height, "OffsetY");
    if (x != 0 || c.offset_x >= 0) set_integer("OffsetX", x);
    if (y != 0 || c.offset_y >= 0) set_integer("OffsetY", y);
  }

  void configure_trigger() {
    const CameraConfig& c = config;
    if (c.trigger_mode == TriggerMode::kHardware) {
      if (!feature_name({"TriggerSelector"}).empty())
        set_enumeration("TriggerSelector", "FrameStart");
      set_enumeration("TriggerSource", c.trigger_source);
      set_enumeration("TriggerActivation", c.trigger_activation);
      set_enumeration("TriggerMode", "On");
      return;
    }
    if (!feature_name({"TriggerMode"}).empty()) {
      if (!feature_name({"TriggerSelector"}).empty())
        set_enumeration("TriggerSelector", "FrameStart");
      set_enumeration("TriggerMode", "Off");
    }
    if (!feature_name({"AcquisitionFrameRateEnable"}).empty()) {
      ErrorSlot e;
      arv_camera_set_boolean(camera.get(), "AcquisitionFrameRateEnable", TRUE, e.out());
      if (e.failed())
        refuse("AcquisitionFrameRateEnable", "true", "rejected (" + e.message() + ")", "");
    }
    set_float({"AcquisitionFrameRate", "AcquisitionFrameRateAbs"}, c.frame_rate_hz);
  }

  void configure_transport() {
    const CameraConfig& c = config;
    if (!gige) return;
    ErrorSlot e;
    if (c.packet_size > 0) {
      arv_camera_gv_set_packet_size(camera.get(), c.packet_size, e.out());
      const guint now = arv_camera_gv_get_packet_size(camera.get(), nullptr);
      if (e.failed() || now != static_cast<guint>(c.packet_size)) {
        refuse("GevSCPSPacketSize", std::to_string(c.packet_size),
               e.failed() ? "rejected (" + e.message() + ")"
                          : "did not stick (reads back " + std::to_string(now) + ")",
               "");
      }
    } else {
      arv_camera_gv_auto_packet_size(camera.get(), e.out());
      e.check(where() + ": automatic GevSCPSPacketSize");
    }
  }

  void configure_stream() {
    const CameraConfig& c = config;
    ErrorSlot e;
    stream.reset(arv_camera_create_stream(camera.get(), nullptr, nullptr, e.out()));
    e.check(where() + ": cannot create the stream");
    if (stream == nullptr) throw std::runtime_error(where() + ": cannot create the stream");
    if (gige) {
      if (c.socket_buffer_bytes > 0) {
        g_object_set(stream.get(), "socket-buffer", ARV_GV_STREAM_SOCKET_BUFFER_FIXED,
                     "socket-buffer-size", c.socket_buffer_bytes, nullptr);
      } else {
        g_object_set(stream.get(), "socket-buffer", ARV_GV_STREAM_SOCKET_BUFFER_AUTO, nullptr);
      }
      g_object_set(
          stream.get(), "packet-resend",
          c.packet_resend ? ARV_GV_STREAM_PACKET_RESEND_ALWAYS : ARV_GV_STREAM_PACKET_RESEND_NEVER,
          nullptr);
    }
    const guint payload = arv_camera_get_payload(camera.get(), e.out());
    e.check(where() + ": PayloadSize");
    for (int i = 0; i < c.buffer_count; ++i) {
      arv_stream_push_buffer(stream.get(), arv_buffer_new_allocate(payload));
    }
  }

  void open() {
    const std::vector<std::string> found = list_cameras();
    device = choose_device(config.device_id, found);
    ErrorSlot e;
    camera.reset(arv_camera_new(device.c_str(), e.out()));
    if (e.failed() || camera == nullptr) {
      throw std::runtime_error(
          "camera: cannot open '" + device + "' (" + e.message() +
          "); cameras found: " + (found.empty() ? std::string("none") : joined(found, "; ")));
    }
    arv_camera_set_range_check_policy(camera.get(), ARV_RANGE_CHECK_POLICY_ENABLE);
    gige = arv_camera_is_gv_device(camera.get());
  }

  void configure() {
    const CameraConfig& c = config;
    if (c.pixel_format != "Mono8") {
      refuse("PixelFormat", c.pixel_format, "is not supported by avs (decode takes Mono8)",
             "Mono8");
    }
    if (!feature_name({"AcquisitionMode"}).empty())
      set_enumeration("AcquisitionMode", "Continuous");
    set_enumeration("PixelFormat", c.pixel_format);
    configure_region();
    if (c.exposure_time_us > 0) set_float({"ExposureTime", "ExposureTimeAbs"}, c.exposure_time_us);
    if (c.gain >= 0) set_gain(c.gain);
    configure_trigger();
    configure_transport();
    configure_stream();
    describe();
  }

  void describe() {
    const auto text = [](const char* s) { return std::string(s != nullptr ? s : "?"); };
    std::ostringstream s;
    s << text(arv_camera_get_vendor_name(camera.get(), nullptr)) << " "
      << text(arv_camera_get_model_name(camera.get(), nullptr)) << " serial "
      << text(arv_camera_get_device_serial_number(camera.get(), nullptr)) << " ("
      << (gige                                    ? "GigE Vision"
          : arv_camera_is_uv_device(camera.get()) ? "USB3 Vision"
                                                  : "other")
      << ", " << device << "): " << config.pixel_format << " " << config.width << "x"
      << config.height << "+" << arv_camera_get_integer(camera.get(), "OffsetX", nullptr) << "+"
      << arv_camera_get_integer(camera.get(), "OffsetY", nullptr) << ", ";
    if (config.trigger_mode == TriggerMode::kHardware) {
      s << "hardware trigger " << config.trigger_source << " " << config.trigger_activation
        << " at " << config.frame_rate_hz << " Hz (the projector's)";
    } else {
      s << "free-run at " << config.frame_rate_hz << " Hz";
    }
    if (gige) s << ", packet size " << arv_camera_gv_get_packet_size(camera.get(), nullptr);
    s << ", " << config.buffer_count << " buffers of "
      << arv_camera_get_payload(camera.get(), nullptr) << " bytes";
    description = s.str();
  }

  std::uint64_t info(const char* name) const {
    return stream ? arv_stream_get_info_uint64_by_name(stream.get(), name) : 0;
  }
};

AravisCamera::AravisCamera(const CameraConfig& config) : impl_(std::make_shared<Impl>()) {
  impl_->config = config;
  impl_->open();
  impl_->configure();
}

AravisCamera::~AravisCamera() {
  try {
    stop();
  } catch (...) {  // destructors never throw; stop() reports through its caller otherwise
  }
}

const std::string& AravisCamera::description() const {
  return impl_->description;
}

std::string AravisCamera::untested_path() const {
  if (!impl_->gige) {
    return "USB3 Vision (or another non-GigE transport): NOT exercised by avs's tests, which "
           "run GigE Vision over loopback against Aravis's fake camera";
  }
  const char* address = arv_camera_get_device_id(impl_->camera.get(), nullptr);
  const std::string id = address != nullptr ? address : "";
  if (impl_->device.rfind("127.", 0) == 0 || id.find("Fake") != std::string::npos) return {};
  return "GigE Vision on a real network interface: packet size, socket buffer and packet "
         "resend are exercised by avs's tests only over loopback (the fake camera never "
         "resends)";
}
bool AravisCamera::is_gige() const {
  return impl_->gige;
}

void AravisCamera::start() {
  ErrorSlot e;
  arv_camera_start_acquisition(impl_->camera.get(), e.out());
  e.check(impl_->where() + ": AcquisitionStart");
  impl_->acquiring = true;
}

void AravisCamera::set_exposure_and_gain(double exposure_us, double gain) {
  // GenICam control goes over GVCP (or the USB3 Vision control endpoint), not the stream:
  // the capture thread's buffers are not touched.
  if (exposure_us > 0) impl_->set_float({"ExposureTime", "ExposureTimeAbs"}, exposure_us);
  if (gain >= 0) impl_->set_gain(gain);
}

void AravisCamera::stop() {
  if (!impl_->acquiring) return;
  impl_->acquiring = false;
  ErrorSlot e;
  arv_camera_stop_acquisition(impl_->camera.get(), e.out());
  e.check(impl_->where() + ": AcquisitionStop");
}

/// A stream buffer while it is out of the stream. Back into the stream at the first next()
/// after its frame's last holder let go, or when it is destroyed (a frame still held after the
/// AravisCamera is gone: it keeps the stream alive until then, as a frame always did).
struct AravisCamera::Lease {
  ArvBuffer* buffer = nullptr;
  std::shared_ptr<Impl> impl;
  bool out = false;

  Lease(ArvBuffer* b, std::shared_ptr<Impl> i) : buffer(b), impl(std::move(i)) {}
  Lease(const Lease&) = delete;
  Lease& operator=(const Lease&) = delete;
  ~Lease() {
    if (out) arv_stream_push_buffer(impl->stream.get(), buffer);
  }
};

int AravisCamera::return_released_buffers() {
  int held = 0;
  for (const auto& lease : leases_) {
    if (!lease->out) continue;
    // Only leases_ holds it: nobody can take a new reference. The fence orders Aravis's
    // writes into the buffer after the last holder's reads (its release of the count).
    if (lease.use_count() == 1) {
      std::atomic_thread_fence(std::memory_order_acquire);
      lease->out = false;
      arv_stream_push_buffer(impl_->stream.get(), lease->buffer);
    } else {
      ++held;
    }
  }
  return held;
}

const std::shared_ptr<AravisCamera::Lease>& AravisCamera::lease_of(void* buffer) {
  for (const auto& lease : leases_) {
    if (lease->buffer == buffer) return lease;
  }
  leases_.push_back(std::make_shared<Lease>(static_cast<ArvBuffer*>(buffer), impl_));
  return leases_.back();
}

std::optional<CapturedFrame> AravisCamera::next(std::chrono::milliseconds timeout) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  ArvBuffer* buffer = nullptr;
  for (;;) {
    if (release_hook_) release_hook_();
    const int held = return_released_buffers();
    const auto now = std::chrono::steady_clock::now();
    auto wait = std::chrono::duration_cast<std::chrono::microseconds>(deadline - now);
    // With (nearly) every buffer held, one let go while we wait would stay out until the wait
    // ends: wait in short steps then, returning buffers between them.
    if (held >= impl_->config.buffer_count - 1) {
      wait = std::min(wait, std::chrono::microseconds(1000));
    }
    wait = std::max(wait, std::chrono::microseconds(0));
    buffer = arv_stream_timeout_pop_buffer(impl_->stream.get(), static_cast<guint64>(wait.count()));
    if (buffer != nullptr || std::chrono::steady_clock::now() >= deadline) break;
  }
  if (buffer == nullptr) return std::nullopt;
  const std::shared_ptr<Lease>& lease = lease_of(buffer);
  lease->out = true;
  CapturedFrame f;
  const ArvBufferStatus status = arv_buffer_get_status(buffer);
  f.complete = status == ARV_BUFFER_STATUS_SUCCESS;
  f.status = status_text(status);
  f.frame_id = arv_buffer_get_frame_id(buffer);
  f.camera_timestamp_ns = static_cast<std::int64_t>(arv_buffer_get_timestamp(buffer));
  f.host_timestamp_ns = static_cast<std::int64_t>(arv_buffer_get_system_timestamp(buffer));
  if (f.complete) {
    if (arv_buffer_get_image_pixel_format(buffer) != ARV_PIXEL_FORMAT_MONO_8) {
      f.complete = false;
      f.status = "pixel format is not Mono8";
    }
    size_t size = 0;
    f.data = static_cast<const std::uint8_t*>(arv_buffer_get_image_data(buffer, &size));
    f.size = size;
    f.width = arv_buffer_get_image_width(buffer);
    f.height = arv_buffer_get_image_height(buffer);
    f.stride = f.width;
    if (f.data == nullptr || size < static_cast<size_t>(f.width) * static_cast<size_t>(f.height)) {
      f.complete = false;
      f.status = "image data smaller than its width x height";
    }
  }
  // Aliases the buffer's lease: no allocation.
  f.lease = std::shared_ptr<const void>(lease, buffer);
  return f;
}

StreamCounters AravisCamera::counters() const {
  StreamCounters c;
  guint64 completed = 0, failures = 0, underruns = 0;
  if (impl_->stream) {
    arv_stream_get_statistics(impl_->stream.get(), &completed, &failures, &underruns);
  }
  c.completed = completed;
  c.failures = failures;
  c.underruns = underruns;
  if (impl_->gige) {
    c.timeouts = impl_->info("n_timeouts");
    c.missing_frames = impl_->info("n_missing_frames");
    c.resent_packets = impl_->info("n_resent_packets");
    c.missing_packets = impl_->info("n_missing_packets");
    c.resend_requests = impl_->info("n_resend_requests");
  }
  return c;
}

}  // namespace avs::camera
