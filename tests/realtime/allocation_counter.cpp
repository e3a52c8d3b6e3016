#include "allocation_counter.hpp"

#include <atomic>
#include <cerrno>
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

// Heap allocations go through malloc (operator new, std::vector, Eigen, nanoflann's pool),
// calloc and realloc, or, aligned, through memalign, aligned_alloc and posix_memalign: glibc
// lets a program replace all of them; these count and forward to glibc's own.
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
// Aligned allocations (operator new for over-aligned types, Eigen's aligned types) do not go
// through malloc in glibc: counted here too.
void* __libc_memalign(std::size_t, std::size_t);
void* memalign(std::size_t alignment, std::size_t size) {
  count();
  return __libc_memalign(alignment, size);
}
void* aligned_alloc(std::size_t alignment, std::size_t size) {
  count();
  return __libc_memalign(alignment, size);
}
int posix_memalign(void** out, std::size_t alignment, std::size_t size) {
  count();
  if (alignment % sizeof(void*) != 0 || (alignment & (alignment - 1)) != 0) return EINVAL;
  void* p = __libc_memalign(alignment, size);
  if (p == nullptr) return ENOMEM;
  *out = p;
  return 0;
}
}
