// A container: one process hosting several components. Samples published inside the
// container reach its other components as the same shared buffer (no copy, no
// serialisation); other processes get them over DDS. The container, not the component,
// chooses the threading (one lane for all, or one per component) and the clock.
#pragma once

#include <atomic>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "avs/graph/graph.hpp"
#include "avs/runtime/component.hpp"
#include "avs/runtime/scheduler.hpp"

namespace avs::runtime {

class Container {
 public:
  /// Prepares the container `spec` of `graph` (nothing runs yet).
  Container(const graph::Graph& graph, const graph::ContainerSpec& spec);
  Container(const Container&) = delete;
  Container& operator=(const Container&) = delete;
  ~Container();

  /// Constructs and activates every component, then runs until stop() or the graph's
  /// duration. Returns 0 on a clean stop, 1 if a component failed (reported on stderr).
  int run();

  /// Thread-safe; may be called from another thread (not from a signal handler).
  void stop();

  const std::string& name() const { return spec_.name; }

  /// The container's clock (sim or wall time); thread-safe.
  Time now() const;

  /// The component instance named `name` (after run() has constructed it), for tests.
  Component* find_component(const std::string& name) const;

  struct Impl;

 private:
  const graph::Graph& graph_;
  const graph::ContainerSpec& spec_;
  std::unique_ptr<Impl> impl_;
};

}  // namespace avs::runtime
