// Samples whose bytes are lent, not copied: a camera's frame published with its image sequence
// pointing into the driver's buffer, the buffer kept out of the driver's pool (a lease) until
// the last subscriber let go. The samples (their strings included) are kept from frame to frame,
// like SamplePool's, so lending a frame allocates nothing once warm (issue 16 section 3).
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include <dds/dds.h>

#include "avs/msg/type_support.hpp"

namespace avs::runtime {

/// lend() hands out a sample of T whose byte sequence `data_of(sample)` points at the caller's
/// bytes and which holds the caller's lease. A kept sample nobody holds any more lets go of its
/// lease at the next lend() or release_unused() (where the buffer goes back to its driver: the
/// owner calls release_unused() before and while it waits for the next buffer, e.g. through
/// AravisCamera::set_release_hook). Beyond `max_kept` samples
/// in flight a sample is made for one use and lets go of its lease with its last holder. A
/// reused sample keeps its last message's values: the caller sets every field (set_string reuses
/// the strings' storage). Used from one thread; holders may be on any.
template <class T>
class LentSamplePool {
 public:
  using DataOf = dds_sequence_uint8& (*)(T&);

  explicit LentSamplePool(DataOf data_of, std::size_t max_kept = 8)
      : data_of_(data_of), max_kept_(max_kept) {}

  /// Lets go of the leases of kept samples that nobody holds any more.
  void release_unused() {
    for (const auto& slot : kept_) {
      if (slot->lease && slot.use_count() == 1) {
        // Only the pool holds it: nobody can take a new reference. The fence orders the
        // buffer's next use after the last holder's reads (its release of the count).
        std::atomic_thread_fence(std::memory_order_acquire);
        slot->lease.reset();
      }
    }
  }

  /// A sample whose byte sequence is `size` bytes at `data` (not copied, not freed by the
  /// sample), holding `lease` while it is held.
  std::shared_ptr<T> lend(const std::uint8_t* data, std::size_t size,
                          std::shared_ptr<const void> lease) {
    release_unused();
    std::shared_ptr<Slot> slot;
    for (const auto& kept : kept_) {
      if (kept.use_count() == 1) {
        std::atomic_thread_fence(std::memory_order_acquire);  // as in release_unused()
        slot = kept;
        break;
      }
    }
    if (!slot) {
      slot = std::make_shared<Slot>(data_of_);
      if (kept_.size() < max_kept_) kept_.push_back(slot);
    }
    dds_sequence_uint8& bytes = data_of_(slot->sample);
    bytes._buffer = const_cast<std::uint8_t*>(data);
    bytes._length = bytes._maximum = static_cast<std::uint32_t>(size);
    bytes._release = false;
    slot->lease = std::move(lease);
    return std::shared_ptr<T>(slot, &slot->sample);  // aliases the slot: no allocation
  }

  /// Samples kept for reuse (at most max_kept).
  std::size_t kept() const { return kept_.size(); }

 private:
  struct Slot {
    explicit Slot(DataOf d) : data_of(d) {}
    Slot(const Slot&) = delete;
    Slot& operator=(const Slot&) = delete;
    ~Slot() {
      dds_sequence_uint8& bytes = data_of(sample);
      bytes._buffer = nullptr;  // lent, not ours
      bytes._length = bytes._maximum = 0;
      dds_sample_free(&sample, msg::TypeSupport<T>::descriptor(), DDS_FREE_CONTENTS);
    }
    T sample{};  // zeroed, as dds_alloc would
    std::shared_ptr<const void> lease;
    DataOf data_of;
  };

  DataOf data_of_;
  std::size_t max_kept_;
  std::vector<std::shared_ptr<Slot>> kept_;
};

}  // namespace avs::runtime
