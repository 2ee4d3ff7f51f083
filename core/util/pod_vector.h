// A growable array of trivially copyable elements stored with malloc and
// grown with realloc, for the refinement's largest per-id arrays (tet slots,
// circumcentres, cell memos, the location graph's link pools).
//
// Why not std::vector: growing a vector allocates the new block, copies and
// only then frees the old one, so for a moment the old and the new array are
// both resident. For the largest array of a run that moment is the run's peak
// (measured: a 1 GB array grown 1.25x four times peaks at 4.0 GB as a
// vector, 2.5 GB with realloc). glibc serves blocks of 32 MB and more with
// mmap and grows them with mremap, which moves the pages instead of copying
// them: no second copy, no copying time.
//
// The interface is the subset of std::vector the callers use. resize()
// value-initialises new elements as std::vector does; reserve() makes the
// capacity exactly the request (callers choose their own growth steps,
// util::GrowExactly / ReserveForAppend). Elements must be trivially copyable
// (realloc moves bytes).
#pragma once

#include <malloc.h>

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <new>
#include <type_traits>
#include <utility>

namespace svrc::util {

// Heap accounting for PodVector's blocks, which bypass operator new: when
// set (the server's per-job memory budget, server/memory_accounting.h), it is
// called on the allocating thread with the change in usable bytes each time a
// PodVector allocates, grows, shrinks or frees its block.
using PodHeapHook = void (*)(int64_t delta_bytes);
inline std::atomic<PodHeapHook> pod_heap_hook{nullptr};

template <typename T>
class PodVector {
  static_assert(std::is_trivially_copyable_v<T>, "realloc moves the bytes");
  // Over-aligned elements (a cache-line record) get alignof(T) - 1 bytes of
  // slack in front, and a realloc that lands at another offset is followed by
  // one memmove.
  static constexpr size_t kSlack = alignof(T) <= alignof(std::max_align_t) ? 0 : alignof(T) - 1;

 public:
  using value_type = T;
  using size_type = size_t;
  using iterator = T*;
  using const_iterator = const T*;

  PodVector() = default;
  explicit PodVector(size_t n) { resize(n); }
  PodVector(size_t n, const T& v) { resize(n, v); }
  PodVector(const PodVector& o) {
    reserve(o.size_);
    if (o.size_ > 0) std::memcpy(static_cast<void*>(data_), o.data_, o.size_ * sizeof(T));
    size_ = o.size_;
  }
  PodVector(PodVector&& o) noexcept
      : raw_(std::exchange(o.raw_, nullptr)),
        data_(std::exchange(o.data_, nullptr)),
        size_(std::exchange(o.size_, 0)),
        cap_(std::exchange(o.cap_, 0)) {}
  PodVector& operator=(const PodVector& o) {
    if (this != &o) {
      PodVector copy(o);
      swap(copy);
    }
    return *this;
  }
  PodVector& operator=(PodVector&& o) noexcept {
    if (this != &o) {
      Release(raw_);
      raw_ = std::exchange(o.raw_, nullptr);
      data_ = std::exchange(o.data_, nullptr);
      size_ = std::exchange(o.size_, 0);
      cap_ = std::exchange(o.cap_, 0);
    }
    return *this;
  }
  ~PodVector() { Release(raw_); }

  size_t size() const { return size_; }
  size_t capacity() const { return cap_; }
  bool empty() const { return size_ == 0; }
  T* data() { return data_; }
  const T* data() const { return data_; }
  T& operator[](size_t i) { return data_[i]; }
  const T& operator[](size_t i) const { return data_[i]; }
  T& back() { return data_[size_ - 1]; }
  const T& back() const { return data_[size_ - 1]; }
  T* begin() { return data_; }
  T* end() { return data_ + size_; }
  const T* begin() const { return data_; }
  const T* end() const { return data_ + size_; }

  void reserve(size_t n) {
    if (n > cap_) Reallocate(n);
  }
  void resize(size_t n) {
    if (n > cap_) reserve(n);
    for (size_t i = size_; i < n; ++i) new (data_ + i) T();
    size_ = n;
  }
  void resize(size_t n, const T& v) {
    if (n > cap_) reserve(n);
    for (size_t i = size_; i < n; ++i) new (data_ + i) T(v);
    size_ = n;
  }
  void assign(size_t n, const T& v) {
    size_ = 0;
    resize(n, v);
  }
  void push_back(const T& v) {
    if (size_ == cap_) {
      const T copy = v;  // v may live in this array
      reserve(cap_ + cap_ / 4 + 16);  // 1.25x: realloc grows a large block in place (mremap)
      new (data_ + size_++) T(copy);
      return;
    }
    new (data_ + size_++) T(v);
  }
  void pop_back() { --size_; }
  void clear() { size_ = 0; }
  // Returns the capacity beyond size() to the allocator (realloc shrinks in
  // place: mremap for a large block).
  void shrink_to_fit() {
    if (size_ == cap_) return;
    if (size_ == 0) {
      Release(raw_);
      raw_ = nullptr;
      data_ = nullptr;
      cap_ = 0;
      return;
    }
    Reallocate(size_);
  }
  void swap(PodVector& o) noexcept {
    std::swap(raw_, o.raw_);
    std::swap(data_, o.data_);
    std::swap(size_, o.size_);
    std::swap(cap_, o.cap_);
  }

 private:
  static void Release(void* raw) {
    if (raw == nullptr) return;
    if (const PodHeapHook hook = pod_heap_hook.load(std::memory_order_relaxed)) {
      hook(-static_cast<int64_t>(malloc_usable_size(raw)));
    }
    std::free(raw);
  }
  void Reallocate(size_t n) {
    const size_t old_offset = raw_ == nullptr ? 0 : reinterpret_cast<char*>(data_) - static_cast<char*>(raw_);
    const PodHeapHook hook = pod_heap_hook.load(std::memory_order_relaxed);
    const int64_t before = hook != nullptr && raw_ != nullptr ? static_cast<int64_t>(malloc_usable_size(raw_)) : 0;
    void* p = std::realloc(raw_, n * sizeof(T) + kSlack);
    if (p == nullptr) throw std::bad_alloc();
    if (hook != nullptr) hook(static_cast<int64_t>(malloc_usable_size(p)) - before);
    char* base = static_cast<char*>(p);
    const size_t offset = kSlack == 0 ? 0 : (alignof(T) - reinterpret_cast<uintptr_t>(base) % alignof(T)) % alignof(T);
    if (offset != old_offset && size_ > 0) std::memmove(base + offset, base + old_offset, size_ * sizeof(T));
    raw_ = p;
    data_ = reinterpret_cast<T*>(base + offset);
    cap_ = n;
  }

  void* raw_ = nullptr;  // the malloc'd block; data_ is raw_ aligned up to alignof(T)
  T* data_ = nullptr;
  size_t size_ = 0;
  size_t cap_ = 0;
};

}  // namespace svrc::util
