#include "server/memory_accounting.h"

#include <malloc.h>

#include <cstdlib>
#include <new>

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

void BindThreadMemory(JobMemory* memory) { t_memory = memory; }
bool MemoryAccountingActive() { return SVRC_COUNT_ALLOCATIONS != 0; }

namespace internal {
inline void Count(void* p) {
  JobMemory* m = t_memory;
  if (m == nullptr || p == nullptr) return;
  const int64_t now =
      m->bytes.fetch_add(static_cast<int64_t>(malloc_usable_size(p)), std::memory_order_relaxed) +
      static_cast<int64_t>(malloc_usable_size(p));
  int64_t peak = m->peak.load(std::memory_order_relaxed);
  while (now > peak && !m->peak.compare_exchange_weak(peak, now, std::memory_order_relaxed)) {
  }
}
inline void Uncount(void* p) {
  JobMemory* m = t_memory;
  if (m == nullptr || p == nullptr) return;
  m->bytes.fetch_sub(static_cast<int64_t>(malloc_usable_size(p)), std::memory_order_relaxed);
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
