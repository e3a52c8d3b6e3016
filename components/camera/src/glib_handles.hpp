// RAII for glib/GObject handles and GError, for the Aravis .cpp files of this folder only
// (private: public headers of avs_camera never include glib or Aravis).
#pragma once

#include <glib-object.h>

#include <memory>
#include <stdexcept>
#include <string>
#include <string_view>

namespace avs::camera::detail {

/// Owns one reference to a GObject (g_object_unref on destruction).
struct GObjectUnref {
  void operator()(gpointer object) const {
    if (object != nullptr) g_object_unref(object);
  }
};
template <class T>
using GObjectPtr = std::unique_ptr<T, GObjectUnref>;

/// A GError** out-parameter that frees what it gets.
class ErrorSlot {
 public:
  ErrorSlot() = default;
  ErrorSlot(const ErrorSlot&) = delete;
  ErrorSlot& operator=(const ErrorSlot&) = delete;
  ~ErrorSlot() { clear(); }

  GError** out() {
    clear();
    return &error_;
  }
  bool failed() const { return error_ != nullptr; }
  std::string message() const { return error_ != nullptr ? error_->message : std::string(); }
  void clear() {
    if (error_ != nullptr) g_error_free(error_);
    error_ = nullptr;
  }
  /// Throws std::runtime_error("<what>: <message>") when the call failed.
  void check(std::string_view what) {
    if (!failed()) return;
    std::string text = std::string(what) + ": " + message();
    clear();
    throw std::runtime_error(text);
  }

 private:
  GError* error_ = nullptr;
};

/// g_free on destruction (arrays Aravis returns as "dup").
struct GFree {
  void operator()(gpointer p) const { g_free(p); }
};
template <class T>
using GFreePtr = std::unique_ptr<T, GFree>;

}  // namespace avs::camera::detail
