#include "avs/deploy/publisher_watch.hpp"

#include <dds/dds.h>

#include <algorithm>
#include <chrono>

#include "avs/runtime/error.hpp"

namespace avs::deploy {

PublisherWatch::PublisherWatch(int domain, const std::string& cyclone_xml,
                               std::vector<std::string> topics, Callback callback)
    : topics_(std::move(topics)), callback_(std::move(callback)) {
  if (!cyclone_xml.empty()) {
    const dds_entity_t d =
        dds_create_domain(static_cast<dds_domainid_t>(domain), cyclone_xml.c_str());
    if (d < 0 && d != DDS_RETCODE_PRECONDITION_NOT_MET) {
      runtime::check_dds(d, "create DDS domain " + std::to_string(domain) + " for the watch");
    }
  }
  participant_ = dds_create_participant(static_cast<dds_domainid_t>(domain), nullptr, nullptr);
  if (participant_ < 0) {
    if (domain_ > 0) dds_delete(domain_);
    runtime::check_dds(participant_,
                       "create the watch participant on domain " + std::to_string(domain));
  }
  reader_ = dds_create_reader(participant_, DDS_BUILTIN_TOPIC_DCPSPUBLICATION, nullptr, nullptr);
  if (reader_ < 0) {
    dds_delete(participant_);
    if (domain_ > 0) dds_delete(domain_);
    runtime::check_dds(reader_, "create a DCPSPublication reader");
  }
  thread_ = std::thread([this] { run(); });
}

PublisherWatch::~PublisherWatch() {
  stop_ = true;
  if (thread_.joinable()) thread_.join();
  dds_delete(participant_);
  // The domain's threads must end here: left to process exit, a security-plugin thread can
  // run into OpenSSL after its atexit clean-up (seen as a segfault in libcrypto).
  if (domain_ > 0) dds_delete(domain_);
}

void PublisherWatch::run() {
  std::map<dds_instance_handle_t, std::string> writers;  // live writers of watched topics
  std::map<std::string, int> reported;                   // topic -> last reported count
  for (const auto& t : topics_) reported[t] = -1;
  constexpr int kBatch = 32;
  void* samples[kBatch] = {};
  dds_sample_info_t infos[kBatch];
  while (!stop_) {
    for (;;) {
      const int n = dds_take(reader_, samples, infos, kBatch, kBatch);
      if (n <= 0) break;
      for (int i = 0; i < n; ++i) {
        const auto handle = infos[i].instance_handle;
        if (infos[i].instance_state != DDS_IST_ALIVE) {
          writers.erase(handle);
        } else if (infos[i].valid_data) {
          const auto* ep = static_cast<const dds_builtintopic_endpoint_t*>(samples[i]);
          const std::string topic = ep->topic_name != nullptr ? ep->topic_name : "";
          if (std::find(topics_.begin(), topics_.end(), topic) != topics_.end()) {
            writers[handle] = topic;
          }
        }
      }
      dds_return_loan(reader_, samples, n);
    }
    for (auto& [topic, last] : reported) {
      // [&name = topic]: clang 14 (the fuzz build) cannot capture a structured binding.
      const int live = static_cast<int>(
          std::count_if(writers.begin(), writers.end(),
                        [&name = topic](const auto& w) { return w.second == name; }));
      if (last < 0 && live == 0) continue;  // never seen yet: nothing to report
      // Report the first writer seen, every loss of the last writer, and every return.
      if (last <= 0 ? live > 0 : live == 0) callback_(Event{topic, live, live == 0});
      last = live;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
}

}  // namespace avs::deploy
