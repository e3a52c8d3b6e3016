// Open, configure, validate, start, watch, reopen (projector_link.hpp).
#include "avs/projector/projector_link.hpp"

namespace avs::projector {

namespace {

LinkEvent info(std::string text) {
  return {LinkEvent::Level::kInfo, std::move(text)};
}
LinkEvent warn(std::string text) {
  return {LinkEvent::Level::kWarn, std::move(text)};
}
LinkEvent error(std::string text) {
  return {LinkEvent::Level::kError, std::move(text)};
}

}  // namespace

const char* link_state_name(LinkState s) {
  switch (s) {
    case LinkState::kDisconnected:
      return "disconnected";
    case LinkState::kRunning:
      return "running";
    case LinkState::kRefused:
      return "refused";
  }
  return "unknown";
}

ProjectorLink::ProjectorLink(LinkConfig config, TransportOpener opener)
    : config_(std::move(config)), opener_(std::move(opener)) {
  if (const std::string problem = check(config_.sequence); !problem.empty()) {
    throw std::invalid_argument("projector sequence: " + problem);
  }
}

ProjectorLink::~ProjectorLink() {
  (void)close();
}

std::vector<LinkEvent> ProjectorLink::close() {
  std::vector<LinkEvent> events;
  if (client_ && state_ == LinkState::kRunning) {
    try {
      client_->stop();
      events.push_back(info("sequence stopped"));
    } catch (const Dlpc350Error& e) {
      events.push_back(warn(std::string("stop at close: ") + e.what()));
    }
  }
  drop_device();
  state_ = LinkState::kDisconnected;
  return events;
}

void ProjectorLink::drop_device() {
  client_.reset();
  transport_.reset();
}

std::vector<LinkEvent> ProjectorLink::step(SteadyTime now) {
  std::vector<LinkEvent> events;
  if (state_ == LinkState::kDisconnected) {
    if (!next_attempt_ || now >= *next_attempt_) {
      next_attempt_ = now + config_.reconnect_period;
      connect(events);
      if (state_ == LinkState::kRunning) next_status_ = now + config_.status_period;
    }
  } else if (state_ == LinkState::kRunning && (!next_status_ || now >= *next_status_)) {
    next_status_ = now + config_.status_period;
    poll_status(events);
    if (state_ == LinkState::kDisconnected) next_attempt_ = now + config_.reconnect_period;
  }
  return events;
}

void ProjectorLink::connect(std::vector<LinkEvent>& events) {
  std::string why_not;
  transport_ = opener_(why_not);
  if (!transport_) {
    ++counters_.connect_failures;
    last_error_ = "cannot open the projector: " + why_not;
    // One line per outage, not one per attempt.
    if (!open_failure_reported_) {
      events.push_back(warn(last_error_ + "; retrying every " +
                            std::to_string(config_.reconnect_period.count()) + " ms"));
      open_failure_reported_ = true;
    }
    return;
  }
  open_failure_reported_ = false;
  description_ = transport_->description();
  client_ = std::make_unique<Dlpc350Client>(*transport_, config_.usb_timeout,
                                            config_.match_reply_sequence);
  try {
    const DeviceStatus status = client_->read_status();
    status_words_ = status.words();
    events.push_back(info("opened " + description_ + ": " + status_words_));
    const Validation v = client_->configure(config_.sequence, config_.max_validate_polls);
    validation_words_ = join_words(projector::validation_words(v));
    if (!v.valid()) {
      state_ = LinkState::kRefused;
      last_error_ = "the controller refused the sequence (LUT_VALID " + hex(v.bits) +
                    "): " + validation_words_;
      events.push_back(error(last_error_ + "; it is not started"));
      return;
    }
    if (!v.clean()) events.push_back(warn("sequence valid with " + validation_words_));
    client_->start();
    state_ = LinkState::kRunning;
    consecutive_timeouts_ = 0;
    ++counters_.connects;
    const SequenceConfig& s = config_.sequence;
    events.push_back(info("sequence started: " + std::to_string(s.pattern_count) +
                          " 1-bit patterns from flash image " +
                          std::to_string(s.first_flash_image) + ", exposure " +
                          std::to_string(s.exposure_us) + " us, period " +
                          std::to_string(s.frame_period_us) + " us, trigger out 1 per pattern"));
  } catch (const Dlpc350Error& e) {
    on_error(e, events);
  }
}

void ProjectorLink::poll_status(std::vector<LinkEvent>& events) {
  try {
    const DeviceStatus status = client_->read_status();
    ++counters_.status_reads;
    consecutive_timeouts_ = 0;
    std::string words = status.words();
    const bool fault = !status.ok() || !status.running();
    if (fault) ++counters_.status_faults;
    // Log a status only when it changes (a fault that stays is one line).
    if (words != status_words_) {
      events.push_back(fault ? error("status: " + words) : info("status: " + words));
    }
    status_words_ = std::move(words);
  } catch (const Dlpc350Error& e) {
    on_error(e, events);
  }
}

void ProjectorLink::on_error(const Dlpc350Error& e, std::vector<LinkEvent>& events) {
  last_error_ = e.what();
  using Kind = Dlpc350Error::Kind;
  switch (e.kind()) {
    case Kind::kTimeout:
      ++counters_.timeouts;
      ++consecutive_timeouts_;
      break;
    case Kind::kNack:
      ++counters_.nacks;
      break;
    case Kind::kBadReply:
      ++counters_.bad_replies;
      break;
    case Kind::kDisconnected:
      break;
  }
  const bool lost = e.kind() == Kind::kDisconnected ||
                    consecutive_timeouts_ >= config_.timeouts_before_lost ||
                    state_ != LinkState::kRunning;  // failed while configuring: start over
  if (!lost) {
    events.push_back(warn(last_error_));
    return;
  }
  if (state_ == LinkState::kRunning) ++counters_.disconnects;
  events.push_back(error(last_error_ + "; closing the device, reopening every " +
                         std::to_string(config_.reconnect_period.count()) + " ms"));
  drop_device();
  state_ = LinkState::kDisconnected;
  consecutive_timeouts_ = 0;
}

}  // namespace avs::projector
