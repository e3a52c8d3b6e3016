// Samples shared between components without copies: a sample is allocated once, filled
// by its publisher, then handed around as std::shared_ptr<const T>.
#pragma once

#include <atomic>
#include <cstring>
#include <memory>
#include <span>
#include <string_view>
#include <vector>

#include <dds/dds.h>

#include "avs/msg/type_support.hpp"

namespace avs::runtime {

template <class T>
using SamplePtr = std::shared_ptr<const T>;

/// A zeroed sample of the C message type T; strings and sequences it gets are freed with it.
template <class T>
std::shared_ptr<T> make_sample() {
  void* raw = dds_alloc(sizeof(T));  // dds_alloc zeroes
  return std::shared_ptr<T>(static_cast<T*>(raw), [](T* p) {
    dds_sample_free(p, msg::TypeSupport<T>::descriptor(), DDS_FREE_ALL);
  });
}

/// Samples of T reused from message to message, so that a component publishing every frame
/// allocates nothing once warm (issue 16 section 3). acquire() hands out a sample that no
/// subscriber holds any more, else a new one (kept while fewer than `max_kept` are). A reused
/// sample keeps the values and storage of its last message: the publisher sets every field, and
/// sizes its sequences with resize_sequence and its strings with set_string, which reuse the
/// storage. One pool per publisher, used from the component's own callbacks only.
template <class T>
class SamplePool {
 public:
  explicit SamplePool(std::size_t max_kept = 8) : max_kept_(max_kept) {}

  std::shared_ptr<T> acquire() {
    for (const auto& sample : kept_) {
      // Only the pool holds it: nobody can take a new reference, so this is stable. The fence
      // orders our writes after the last holder's reads (its release of the count).
      if (sample.use_count() == 1) {
        std::atomic_thread_fence(std::memory_order_acquire);
        return sample;
      }
    }
    std::shared_ptr<T> fresh = make_sample<T>();
    if (kept_.size() < max_kept_) kept_.push_back(fresh);
    return fresh;
  }

 private:
  std::size_t max_kept_;
  std::vector<std::shared_ptr<T>> kept_;
};

/// A zeroed sample of any type given by its descriptor and size (e.g. for dds_take of a type
/// known at run time), freed with everything it gets.
inline std::shared_ptr<void> make_sample(const dds_topic_descriptor_t* descriptor,
                                         std::size_t size) {
  return std::shared_ptr<void>(
      dds_alloc(size), [descriptor](void* p) { dds_sample_free(p, descriptor, DDS_FREE_ALL); });
}

/// Replaces a C string field with a copy of `value`, in the field's own storage when the
/// string there is at least as long (a pooled sample's frame_id, set per message, costs no
/// allocation; the storage was allocated for that string, so it holds strlen + 1 bytes).
inline void set_string(char*& field, std::string_view value) {
  if (field == nullptr || std::strlen(field) < value.size()) {
    dds_free(field);
    field = static_cast<char*>(dds_alloc(value.size() + 1));
  }
  std::memcpy(field, value.data(), value.size());
  field[value.size()] = '\0';
}

inline std::string_view get_string(const char* field) {
  return field ? field : "";
}

/// Resizes a Cyclone sequence (dds_sequence_xxx with _buffer/_length/_maximum/_release).
/// Existing elements are kept; elements past the old maximum are zeroed, those between the old
/// length and the maximum hold what they held (a loaned sample's earlier message: set them).
/// Elements holding pointers must not shrink (use only for plain element types, constant
/// lengths, or grow only).
template <class Seq>
void resize_sequence(Seq& seq, std::uint32_t length) {
  using Elem = std::remove_pointer_t<decltype(seq._buffer)>;
  if (length > seq._maximum) {
    auto* buffer = static_cast<Elem*>(dds_alloc(sizeof(Elem) * length));
    if (seq._buffer != nullptr && seq._length > 0) {
      std::memcpy(buffer, seq._buffer, sizeof(Elem) * seq._length);
    }
    if (seq._release) dds_free(seq._buffer);
    seq._buffer = buffer;
    seq._maximum = length;
    seq._release = true;
  }
  seq._length = length;
}

template <class Seq>
auto as_span(const Seq& seq) {
  return std::span(seq._buffer, seq._length);
}

template <class Seq>
auto as_span(Seq& seq) {
  return std::span(seq._buffer, seq._length);
}

}  // namespace avs::runtime
