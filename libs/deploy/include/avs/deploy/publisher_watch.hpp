// Watches DDS discovery for the writers of given topics and reports when a topic loses its
// last live writer (a host died or its participant's lease expired) and when one comes back.
// `avs launch --host` runs one for the topics its containers read from other hosts.
#pragma once

#include <atomic>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <thread>
#include <vector>

namespace avs::deploy {

class PublisherWatch {
 public:
  struct Event {
    std::string topic;  ///< DDS topic name, "rt/chatter"
    int live_writers = 0;
    bool lost = false;  ///< true: went to 0 writers; false: came back (or first seen)
  };
  using Callback = std::function<void(const Event&)>;

  /// Starts a thread with its own participant on `domain`, configured by `cyclone_xml`
  /// (empty: Cyclone's defaults / CYCLONEDDS_URI). `partition` is not needed: discovery
  /// data is seen across partitions.
  PublisherWatch(int domain, const std::string& cyclone_xml, std::vector<std::string> topics,
                 Callback callback);
  ~PublisherWatch();
  PublisherWatch(const PublisherWatch&) = delete;
  PublisherWatch& operator=(const PublisherWatch&) = delete;

 private:
  void run();
  std::vector<std::string> topics_;
  Callback callback_;
  int domain_ = 0;  ///< the domain created for `cyclone_xml`, deleted with the watch
  int participant_ = 0;
  int reader_ = 0;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

}  // namespace avs::deploy
