// LD_PRELOAD shim for measuring any process's peak heap the way
// svrc_sensitivity_bench measures a run's (issue #5): malloc, calloc,
// realloc, the aligned allocators and free are interposed, glibc's __libc_*
// entry points do the work, and the live total counts malloc_usable_size of
// every block, with its high-water mark. At exit the mark is written to
// stderr as "heap_peak=N" (bytes), or appended to the file named by
// SVRC_HEAP_PEAK_OUT. Used on /usr/bin/tetgen and on the `svrc` CLI, so the
// two are compared on the same measure (bench/RESULTS.md, session 51):
//
//   LD_PRELOAD=build/release/bench/svrc/libsvrc_heap_peak.so tetgen -pq2a1e-5 -Q cube.poly
//
// svrc_sensitivity_bench links the library instead and reads the counters in
// process (svrc_heap_now, svrc_heap_peak, svrc_heap_reset_peak); the report
// at exit is then left out unless SVRC_HEAP_PEAK_OUT is set.
//
// Single counters with relaxed atomics: the processes measured here allocate
// from one thread at a time or sum the same either way.
#define _GNU_SOURCE
#include <errno.h>
#include <malloc.h>
#include <stdatomic.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

extern void* __libc_malloc(size_t);
extern void* __libc_calloc(size_t, size_t);
extern void* __libc_realloc(void*, size_t);
extern void* __libc_memalign(size_t, size_t);
extern void __libc_free(void*);

static _Atomic int64_t g_now = 0;
static _Atomic int64_t g_peak = 0;

static void count(int64_t delta) {
  const int64_t now = atomic_fetch_add_explicit(&g_now, delta, memory_order_relaxed) + delta;
  int64_t peak = atomic_load_explicit(&g_peak, memory_order_relaxed);
  while (now > peak &&
         !atomic_compare_exchange_weak_explicit(&g_peak, &peak, now, memory_order_relaxed, memory_order_relaxed)) {
  }
}

static int64_t usable(void* p) { return p == NULL ? 0 : (int64_t)malloc_usable_size(p); }

void* malloc(size_t n) {
  void* p = __libc_malloc(n);
  count(usable(p));
  return p;
}

void* calloc(size_t n, size_t size) {
  void* p = __libc_calloc(n, size);
  count(usable(p));
  return p;
}

void* realloc(void* old, size_t n) {
  const int64_t before = usable(old);
  void* p = __libc_realloc(old, n);
  if (p != NULL || n == 0) count(usable(p) - before);
  return p;
}

void* memalign(size_t align, size_t n) {
  void* p = __libc_memalign(align, n);
  count(usable(p));
  return p;
}

void* aligned_alloc(size_t align, size_t n) { return memalign(align, n); }

int posix_memalign(void** out, size_t align, size_t n) {
  void* p = __libc_memalign(align, n);
  if (p == NULL) return ENOMEM;
  count(usable(p));
  *out = p;
  return 0;
}

void free(void* p) {
  if (p == NULL) return;
  count(-usable(p));
  __libc_free(p);
}

long long svrc_heap_now(void) { return (long long)atomic_load_explicit(&g_now, memory_order_relaxed); }

long long svrc_heap_peak(void) { return (long long)atomic_load_explicit(&g_peak, memory_order_relaxed); }

void svrc_heap_reset_peak(void) {
  atomic_store_explicit(&g_peak, atomic_load_explicit(&g_now, memory_order_relaxed), memory_order_relaxed);
}

__attribute__((destructor)) static void report(void) {
  const long long peak = svrc_heap_peak();
  const char* path = getenv("SVRC_HEAP_PEAK_OUT");
  const char* preload = getenv("LD_PRELOAD");
  FILE* f = path != NULL ? fopen(path, "a") : NULL;
  if (f != NULL) {
    fprintf(f, "heap_peak=%lld\n", peak);
    fclose(f);
  } else if (preload != NULL && strstr(preload, "svrc_heap_peak") != NULL) {
    char line[64];
    const int len = snprintf(line, sizeof line, "heap_peak=%lld\n", peak);
    if (len > 0) (void)!write(2, line, (size_t)len);
  }
}
