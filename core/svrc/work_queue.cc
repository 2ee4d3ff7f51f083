// Bucketed work queues of thesis §5.1.2 / Figure 3.11. See work_queue.h.
#include "core/svrc/work_queue.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include "core/util/grow.h"

namespace svrc::refine {

const char* EventTypeName(EventType type) {
  switch (type) {
    case EventType::kSkinny: return "skinny";
    case EventType::kEncroached: return "encroached";
    case EventType::kUnresolved: return "unresolved";
    case EventType::kCollar: return "collar";
  }
  return "?";
}

const std::array<int, 10>& WorkQueues::PriorityOrder() {
  using T = EventType;
  static const std::array<int, 10> kOrder = {
      QueueIndex(T::kSkinny, 1),     QueueIndex(T::kSkinny, 2),     QueueIndex(T::kSkinny, 3),
      QueueIndex(T::kEncroached, 2), QueueIndex(T::kEncroached, 1), QueueIndex(T::kUnresolved, 3),
      QueueIndex(T::kUnresolved, 2), QueueIndex(T::kUnresolved, 1), QueueIndex(T::kCollar, 2),
      QueueIndex(T::kCollar, 3)};
  return kOrder;
}

int WorkQueues::BucketOf(double radius) {
  if (!(radius > 0)) return 0;  // radius 0: the lowest bucket
  // ilogb is exact (an exponent extraction): ⌊log₂ r⌋ without rounding issues.
  return std::ilogb(radius) - kMinExp;
}

WorkQueues::WorkQueues() = default;

uint32_t* WorkQueues::Queue::Chunk(int b) {
  std::unique_ptr<uint32_t[]>& c = chunks[b / kChunk];
  if (c == nullptr) [[unlikely]] {
    c = std::make_unique<uint32_t[]>(2 * kChunk);
    std::fill(c.get(), c.get() + 2 * kChunk, kNil);
  }
  return c.get();
}

EventHandle WorkQueues::Enqueue(const WorkEvent& event) {
  const int dim = event.dim;
  bool ok = dim >= 1 && dim <= 3 && std::isfinite(event.radius) && event.radius >= 0;
  if (event.type == EventType::kEncroached && dim == 3) ok = false;
  if (event.type == EventType::kCollar && dim == 1) ok = false;
  if (!ok) {
    ++stats_.rejected;
    return {};
  }
  uint32_t e;
  if (free_head_ != kNil) {
    e = free_head_;
    free_head_ = entries_[e].next;
  } else {
    e = static_cast<uint32_t>(entries_.size());
    util::ReserveForAppend(entries_);
    entries_.emplace_back();
    entries_.back().generation = first_generation_;
  }
  Entry& entry = entries_[e];
  entry.Store(event);
  const int q = QueueIndex(event.type, dim);
  Link(e, q, BucketOf(event.radius));
  ++stats_.pushed[static_cast<int>(event.type)];
  return {EventId(e), entry.generation};
}

void WorkQueues::Link(uint32_t e, int q, int bucket) {
  Entry& entry = entries_[e];
  Queue& queue = queues_[q];
  uint32_t* chunk = queue.Chunk(bucket);
  uint32_t& head = chunk[bucket % kChunk];
  uint32_t& tail = chunk[kChunk + bucket % kChunk];
  entry.queue = static_cast<int16_t>(q);
  entry.bucket = static_cast<int16_t>(bucket);
  entry.next = kNil;
  entry.prev = tail;
  if (entry.prev != kNil) {
    entries_[entry.prev].next = e;
  } else {
    head = e;
  }
  tail = e;
  queue.cursor = std::max(queue.cursor, bucket);
  ++queue_size_[q];
  ++size_;
}

void WorkQueues::Unlink(uint32_t e) {
  Entry& entry = entries_[e];
  Queue& queue = queues_[entry.queue];
  uint32_t* chunk = queue.chunks[entry.bucket / kChunk].get();  // allocated: the entry is in it
  if (entry.prev != kNil) {
    entries_[entry.prev].next = entry.next;
  } else {
    chunk[entry.bucket % kChunk] = entry.next;
  }
  if (entry.next != kNil) {
    entries_[entry.next].prev = entry.prev;
  } else {
    chunk[kChunk + entry.bucket % kChunk] = entry.prev;
  }
  --queue_size_[entry.queue];
  --size_;
  entry.queue = -1;
  entry.prev = entry.next = kNil;
  // The cursor stays: Dequeue walks it down lazily (and counts the walk).
}

void WorkQueues::Free(uint32_t e) {
  Entry& entry = entries_[e];
  ++entry.generation;  // every handle to this event is now stale
  entry.queue = -1;
  entry.next = free_head_;
  free_head_ = e;
}

void WorkQueues::SetNewestFirst(EventType type, int dim, bool newest_first) {
  queues_[QueueIndex(type, dim)].newest_first = newest_first;
}

uint32_t WorkQueues::PopFrom(int q) {
  Queue& queue = queues_[q];
  if (queue_size_[q] == 0) {
    // Nothing left: reset the cursor without walking (counted walks are the
    // ones a non-empty queue needs; Lemma 30).
    queue.cursor = -1;
    return kNil;
  }
  uint64_t walked = 0;
  while (queue.cursor >= 0 && queue.Head(queue.cursor) == kNil) {
    --queue.cursor;
    ++walked;
  }
  stats_.buckets_walked += walked;
  stats_.max_walk_one_op = std::max(stats_.max_walk_one_op, walked);
  assert(queue.cursor >= 0);
  const uint32_t e = queue.newest_first ? queue.Tail(queue.cursor) : queue.Head(queue.cursor);
  Unlink(e);
  return e;
}

std::optional<WorkEvent> WorkQueues::Dequeue() {
  for (int q : PriorityOrder()) {
    if (queue_size_[q] == 0) continue;
    const uint32_t e = PopFrom(q);
    WorkEvent event = entries_[e].Event();
    Free(e);
    ++stats_.popped[static_cast<int>(event.type)];
    return event;
  }
  return std::nullopt;
}

std::optional<WorkEvent> WorkQueues::DequeueLive(
    const std::function<bool(const WorkEvent&)>& is_live) {
  while (true) {
    std::optional<WorkEvent> event = Dequeue();
    if (!event) return std::nullopt;
    if (is_live(*event)) return event;
    ++stats_.stale[static_cast<int>(event->type)];
  }
}

bool WorkQueues::ReleaseIfEmpty() {
  if (size_ != 0 || entries_.capacity() == 0) return false;
  for (const Entry& entry : entries_) first_generation_ = std::max(first_generation_, entry.generation + 1);
  std::vector<Entry>().swap(entries_);
  free_head_ = kNil;
  return true;
}

bool WorkQueues::IsQueued(EventHandle handle) const {
  if (!handle.id.valid() || handle.id.value() >= entries_.size()) return false;
  const Entry& entry = entries_[handle.id.value()];
  return entry.generation == handle.generation && entry.queue >= 0;
}

WorkEvent WorkQueues::Get(EventHandle handle) const {
  assert(IsQueued(handle));
  return entries_[handle.id.value()].Event();
}

void WorkQueues::DecreaseSize(EventHandle handle, double new_radius) {
  if (!IsQueued(handle)) return;
  const uint32_t e = handle.id.value();
  Entry& entry = entries_[e];
  if (!(new_radius < entry.radius) || !(new_radius >= 0)) return;
  ++stats_.decrease_size;
  entry.radius = new_radius;
  const int bucket = BucketOf(new_radius);
  if (bucket == entry.bucket) return;  // same bucket: keep its FIFO position
  const int q = entry.queue;
  const uint64_t walked = static_cast<uint64_t>(entry.bucket - bucket);
  stats_.buckets_walked += walked;
  stats_.max_walk_one_op = std::max(stats_.max_walk_one_op, walked);
  Unlink(e);
  Link(e, q, bucket);
}

void WorkQueues::Refresh(EventHandle handle, uint32_t generation, double radius) {
  if (!IsQueued(handle) || !std::isfinite(radius) || radius < 0) return;
  const uint32_t e = handle.id.value();
  entries_[e].event_generation = generation;
  if (radius <= entries_[e].radius) {
    DecreaseSize(handle, radius);
    return;
  }
  ++stats_.increase_size;
  entries_[e].radius = radius;
  const int bucket = BucketOf(radius);
  if (bucket != entries_[e].bucket) {
    const int q = entries_[e].queue;
    Unlink(e);
    Link(e, q, bucket);
  }
}

void WorkQueues::Remove(EventHandle handle) {
  if (!IsQueued(handle)) return;
  Unlink(handle.id.value());
  Free(handle.id.value());
}

bool WorkQueues::RemoveObjectEvent(EventId id, MeshId mesh, uint32_t object) {
  if (!id.valid() || id.value() >= entries_.size()) return false;
  const Entry& entry = entries_[id.value()];
  if (entry.queue < 0 || entry.mesh != mesh || entry.object != object) return false;
  ++stats_.removed_dead[static_cast<int>(entry.type)];
  Unlink(id.value());
  Free(id.value());
  return true;
}

double WorkQueues::LargestPendingRadius() const {
  double best = 0;
  for (int q = 0; q < kNumQueues; ++q) {
    if (queue_size_[q] == 0) continue;
    const Queue& queue = queues_[q];
    for (int b = queue.cursor; b >= 0; --b) {
      if (queue.Head(b) != kNil) {
        best = std::max(best, std::ldexp(1.0, b + kMinExp));
        break;
      }
    }
  }
  return best;
}

bool WorkQueues::Validate() const {
  size_t total = 0;
  for (int q = 0; q < kNumQueues; ++q) {
    const Queue& queue = queues_[q];
    size_t count = 0;
    for (int b = 0; b < kNumBuckets; ++b) {
      uint32_t prev = kNil;
      for (uint32_t e = queue.Head(b); e != kNil; e = entries_[e].next) {
        const Entry& entry = entries_[e];
        if (entry.queue != q || entry.bucket != b || entry.prev != prev) return false;
        if (BucketOf(entry.radius) != b) return false;
        if (b > queue.cursor) return false;
        prev = e;
        ++count;
      }
      if (queue.Tail(b) != prev) return false;
    }
    if (count != queue_size_[q]) return false;
    total += count;
  }
  return total == size_;
}

}  // namespace svrc::refine
