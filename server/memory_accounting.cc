#include "server/memory_accounting.h"

#include <malloc.h>

#include <cstdlib>
#include <new>

#include "core/util/pod_vector.h"

#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
#define SVRC_COUNT_ALLOCATIONS 0
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer)
#define SVRC_COUNT_ALLOCATIONS 0
#endif
#endif
#ifndef SVRC_COUNT_ALLOCATIONS
#define SVRC_COUNT_ALLOCATIONS 1
#endif

namespace svrc::server {
namespace {
thread_local JobMemory* t_memory = nullptr;
}  // namespace

bool MemoryAccountingActive() { return SVRC_COUNT_ALLOCATIONS != 0; }

namespace internal {
// Adds `delta` bytes to the calling thread's job (if any) and its peak.
void CountDelta(int64_t delta) {
  JobMemory* m = t_memory;
  if (m == nullptr) return;
  const int64_t now = m->bytes.fetch_add(delta, std::memory_order_relaxed) + delta;
  int64_t peak = m->peak.load(std::memory_order_relaxed);
  while (now > peak && !m->peak.compare_exchange_weak(peak, now, std::memory_order_relaxed)) {
  }
}

inline void Count(void* p) {
  if (t_memory == nullptr || p == nullptr) return;
  CountDelta(static_cast<int64_t>(malloc_usable_size(p)));
}

inline void Uncount(void* p) {
  if (t_memory == nullptr || p == nullptr) return;
  CountDelta(-static_cast<int64_t>(malloc_usable_size(p)));
}

inline void* Allocate(std::size_t n) {
  void* p = std::malloc(n == 0 ? 1 : n);
  if (p == nullptr) throw std::bad_alloc();
  Count(p);
  return p;
}
inline void Free(void* p) {
  Uncount(p);
  std::free(p);
}
}  // namespace internal

void BindThreadMemory(JobMemory* memory) {
#if SVRC_COUNT_ALLOCATIONS
  // util::PodVector's blocks (the refinement's largest arrays) come from
  // realloc, not operator new: they report through this hook.
  util::pod_heap_hook.store(&internal::CountDelta, std::memory_order_relaxed);
#endif
  t_memory = memory;
}
}  // namespace svrc::server

#if SVRC_COUNT_ALLOCATIONS
// Replacements of the global allocation functions ([new.delete.single],
// [new.delete.array]); the nothrow and aligned forms of libstdc++ end in
// these or in malloc/free directly, which stay compatible.
void* operator new(std::size_t n) { return svrc::server::internal::Allocate(n); }
void* operator new[](std::size_t n) { return svrc::server::internal::Allocate(n); }
void operator delete(void* p) noexcept { svrc::server::internal::Free(p); }
void operator delete[](void* p) noexcept { svrc::server::internal::Free(p); }
void operator delete(void* p, std::size_t) noexcept { svrc::server::internal::Free(p); }
void operator delete[](void* p, std::size_t) noexcept { svrc::server::internal::Free(p); }
#endif
