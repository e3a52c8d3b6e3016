// Heap allocations counted per thread, for the tests of issue 16 section 3 (no allocation per
// frame after warm-up). allocation_counter.cpp replaces malloc, calloc, realloc and the
// aligned allocators for the whole test program (so operator new, Eigen and nanoflann are all
// counted); only threads that armed the count add to it.
#pragma once

namespace avs::testing {

/// Starts (true) or stops (false) counting this thread's allocations.
void count_allocations_on_this_thread(bool on);
/// Allocations counted since the last reset, over every armed thread.
long counted_allocations();
void reset_counted_allocations();

/// Counts this thread's allocations while it lives (from zero).
class CountAllocations {
 public:
  CountAllocations() {
    reset_counted_allocations();
    count_allocations_on_this_thread(true);
  }
  ~CountAllocations() { count_allocations_on_this_thread(false); }
  CountAllocations(const CountAllocations&) = delete;
  CountAllocations& operator=(const CountAllocations&) = delete;
  long count() const { return counted_allocations(); }
};

}  // namespace avs::testing
