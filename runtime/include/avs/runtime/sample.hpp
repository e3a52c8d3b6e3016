// Samples shared between components without copies: a sample is allocated once, filled
// by its publisher, then handed around as std::shared_ptr<const T>.
#pragma once

#include <cstring>
#include <memory>
#include <span>
#include <string_view>

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

/// A zeroed sample of any type given by its descriptor and size (e.g. for dds_take of a type
/// known at run time), freed with everything it gets.
inline std::shared_ptr<void> make_sample(const dds_topic_descriptor_t* descriptor,
                                         std::size_t size) {
  return std::shared_ptr<void>(
      dds_alloc(size), [descriptor](void* p) { dds_sample_free(p, descriptor, DDS_FREE_ALL); });
}

/// Replaces a C string field with a copy of `value`.
inline void set_string(char*& field, std::string_view value) {
  dds_free(field);
  field = static_cast<char*>(dds_alloc(value.size() + 1));
  std::memcpy(field, value.data(), value.size());
  field[value.size()] = '\0';
}

inline std::string_view get_string(const char* field) { return field ? field : ""; }

/// Resizes a Cyclone sequence (dds_sequence_xxx with _buffer/_length/_maximum/_release).
/// New elements are zeroed; existing ones kept. Elements holding pointers must not shrink
/// (use only for plain element types, or grow only).
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
