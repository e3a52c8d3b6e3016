#include "allocation_counter.hpp"

#include <atomic>
#include <cstddef>

namespace {

// Armed per thread: only the thread running the hot path counts (the servo test's simulated
// amplifiers answer on a thread of their own; a container's DDS threads are not its lanes).
thread_local bool g_counting = false;
std::atomic<long> g_allocations{0};

void count() {
  if (g_counting) g_allocations.fetch_add(1);
}

}  // namespace

namespace avs::testing {
void count_allocations_on_this_thread(bool on) {
  g_counting = on;
}
long counted_allocations() {
  return g_allocations.load();
}
void reset_counted_allocations() {
  g_allocations = 0;
}
}  // namespace avs::testing

// Every heap allocation goes through malloc (operator new, std::vector, Eigen, nanoflann's
// pool): glibc lets a program replace malloc, calloc, realloc and free (and uses them for
// memalign & co.); these count and forward to glibc's own.
extern "C" {
void* __libc_malloc(std::size_t);
void* __libc_calloc(std::size_t, std::size_t);
void* __libc_realloc(void*, std::size_t);
void __libc_free(void*);
void* malloc(std::size_t size) {
  count();
  return __libc_malloc(size);
}
void* calloc(std::size_t n, std::size_t size) {
  count();
  return __libc_calloc(n, size);
}
void* realloc(void* p, std::size_t size) {
  count();
  return __libc_realloc(p, size);
}
void free(void* p) {
  __libc_free(p);
}
}
