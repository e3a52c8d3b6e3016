// What the `camera` component asks of a GenICam camera (docs/devices.md): the GenICam features
// it sets at configure time, the stream's buffers and GigE transport, the stamps and the
// PatternSequencer. Plain struct: the component binds its parameters to these fields.
#pragma once

#include <cstdint>
#include <string>

#include "avs/camera/pattern_sequencer.hpp"

namespace avs::camera {

enum class TriggerMode : std::uint8_t {
  kHardware,  ///< TriggerMode On from trigger_source (the projector's trigger out): the rig
  kFreeRun,   ///< TriggerMode Off, AcquisitionFrameRate = frame_rate_hz
};

enum class StampSource : std::uint8_t {
  kHostMapped,   ///< camera timestamp + the smallest (host arrival - camera timestamp) seen
  kCamera,       ///< the camera's timestamp as it is (a PTP-synchronised camera, the sim camera)
  kHostArrival,  ///< the host's clock when the frame was complete
};

struct CameraConfig {
  std::string device_id;  ///< Aravis device id, serial number or IP address; empty: the only one
  std::string pixel_format = "Mono8";
  int width = 512;  ///< ROI (section 3.1: 512 x 512 at 1000 fps)
  int height = 512;
  int offset_x = -1;  ///< -1: centred on the sensor
  int offset_y = -1;
  double exposure_time_us = 0;  ///< ExposureTime; 0: leave the camera's
  double gain = -1;             ///< Gain; < 0: leave the camera's
  TriggerMode trigger_mode = TriggerMode::kHardware;
  std::string trigger_source = "Line0";
  std::string trigger_activation = "RisingEdge";
  double frame_rate_hz = 1000;  ///< the projector's pattern rate (both modes)
  int packet_size = 0;          ///< GigE GevSCPSPacketSize bytes; 0: Aravis finds the largest
  int socket_buffer_bytes = 0;  ///< GigE receive socket buffer; 0: one payload (Aravis auto)
  bool packet_resend = true;    ///< GigE: ask the camera to resend lost packets
  int buffer_count = 32;        ///< stream buffers, allocated once
  int buffer_timeout_ms = 200;  ///< wait for a frame before checking for stop
  StampSource stamp_source = StampSource::kHostMapped;
  double image_raw_rate_hz = 0;  ///< /camera/image_raw at most this often; 0: never
  SequencerConfig sequencer;
};

}  // namespace avs::camera
