// SVRC's work queues (thesis Figure 3.11, §3.2.1, §5.1.2, Lemmas 30–31): eleven
// bucketed priority queues of gap-ball work events — Skinny₁₋₃, Encroached₁₋₂,
// Unresolved₁₋₃, Collar₁₋₃ — scanned in the priority order of Dequeue.
//
// Inside one queue, events are bucketed by ⌊log₂ r⌋ (ilogb), the largest bucket is
// served first, and a bucket is FIFO (push order) or, per queue on request,
// LIFO (newest first); either way runs are deterministic. The thesis fixes the
// order of buckets, not the order inside one (§5.1.2).
// Events are keys (mesh, object, generation), not balls: whoever pops an event
// decides whether it is stale (lazy deletion, as Triangle's bad-triangle queue
// and Th. Figure 3.4 line 1 "no longer on the Voronoi skeleton").
// DecreaseSize moves a queued event to a smaller bucket in O(1) and counts the
// buckets it skips (Lemma 30's cost; Lemma 31 says it is O(1)).
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <vector>

#include "core/geometry/vec3.h"
#include "core/svrc/ids.h"

namespace svrc::refine {

enum class EventType : uint8_t { kSkinny = 0, kEncroached = 1, kUnresolved = 2, kCollar = 3 };
inline constexpr int kNumEventTypes = 4;
const char* EventTypeName(EventType type);

// One work event: a gap ball of radius `radius` to destroy in mesh `mesh`.
// `dim` selects the queue: the mesh dimension for Skinny, Unresolved and Collar,
// the dimension of the *ball's* feature (1 or 2) for Encroached (guide §3, 3.11).
// `object` is the cell's vertex (Skinny/Unresolved: keyed by cell), the tet
// (a Skinny₃ tet event) or the ball id (Encroached/Collar: keyed by ball);
// `generation` is that object's generation when the event was made, so a
// popped event is stale iff it moved on. The ball's centre is not stored: the
// refiner rebuilds it from the live object at pop (a cell's farthest corner,
// a tet's circumcentre, a ball's centre), which is what the generation
// test guarantees is unchanged.
struct WorkEvent {
  EventType type = EventType::kSkinny;
  uint8_t dim = 3;
  MeshId mesh;
  uint32_t object = 0;
  uint32_t generation = 0;
  double radius = 0;
};

// A handle to a queued event: slot + the slot's generation (a popped or removed
// event's handle goes stale and every operation on it is a no-op).
struct EventHandle {
  EventId id;
  uint32_t generation = 0;
  bool valid() const { return id.valid(); }
};

class WorkQueues {
 public:
  // The eleven queues, indexed type*3 + (dim-1). Collar₁ exists (the thesis
  // counts it) but Dequeue never scans it: 1D collar points are Unresolved₁
  // events (Figure 3.11 scans "Collar 2 to 3"); Enqueue refuses it.
  static constexpr int kNumQueues = 12;  // 4 types × dims 1..3; Encroached₃ unused
  static int QueueIndex(EventType type, int dim) { return static_cast<int>(type) * 3 + (dim - 1); }

  // Figure 3.11's Dequeue order: Skinny 1→3, Encroached 2→1, Unresolved 3→1,
  // Collar 2→3.
  static const std::array<int, 10>& PriorityOrder();

  // Exponent range of buckets: ilogb of positive finite doubles is in
  // [-1074, 1023]; radius 0 goes to the lowest bucket.
  static constexpr int kMinExp = -1075;
  static constexpr int kMaxExp = 1023;
  static constexpr int kNumBuckets = kMaxExp - kMinExp + 1;
  static int BucketOf(double radius);

  WorkQueues();

  // Serves the buckets of queue (type, dim) newest event first (LIFO) instead
  // of oldest first. A refinement's newest events lie next to its latest
  // insertion, whose cells and tets are still in cache (docs/svrc-design.md §8
  // item 52). Takes effect at the next pop.
  void SetNewestFirst(EventType type, int dim, bool newest_first);
  bool NewestFirst(EventType type, int dim) const { return queues_[QueueIndex(type, dim)].newest_first; }

  // Push. Returns an invalid handle (and counts `rejected`) for an event that
  // has no queue: Encroached with dim ∉ {1,2}, Collar₁, dim ∉ {1,2,3}, or a
  // radius that is negative or not finite.
  EventHandle Enqueue(const WorkEvent& event);

  // Pops the highest-priority event (first non-empty queue in PriorityOrder,
  // largest bucket, oldest in the bucket — newest in a NewestFirst queue).
  // nullopt when all are empty.
  std::optional<WorkEvent> Dequeue();

  // Pops events until one is live according to `is_live`; the others are
  // dropped and counted as stale (per type). nullopt when all are empty.
  std::optional<WorkEvent> DequeueLive(const std::function<bool(const WorkEvent&)>& is_live);

  // Lemma 30: lowers the radius of a queued event (a larger radius is ignored:
  // the thesis only ever shrinks events). Moves it to the back of its new bucket;
  // `buckets_walked` grows by the number of buckets between old and new.
  void DecreaseSize(EventHandle handle, double new_radius);

  // ForceInsert's refresh of a cell-keyed event after the cell changed
  // (Figure 3.5): new generation, and DecreaseSize to the new radius. Cells
  // only shrink when points are added, so a larger radius is rounding noise:
  // it is stored in place (same bucket) or re-bucketed and counted as
  // `increase_size`. No-op on a stale handle.
  void Refresh(EventHandle handle, uint32_t generation, double radius);

  // Removes a queued event eagerly (lazy deletion is the norm; this is for
  // callers that hold a handle anyway). No-op on a stale handle.
  void Remove(EventHandle handle);
  // Removes the event queued in slot `id` if it is an event of `object` in
  // `mesh` (any type), for a caller that kept the slot only (4 bytes, not a
  // handle's 8) and knows every event of that object to be stale: it then
  // need not wait in the queue until popped. Returns whether one was removed.
  bool RemoveObjectEvent(EventId id, MeshId mesh, uint32_t object);

  // Frees the storage of the events when none is queued (the slots of a
  // run's peak stay allocated otherwise: 40 B each, up to 2 M on cube
  // --max-volume 1e-6). Every handle made before stays stale: slots made
  // after start at a generation above any handed out. Returns whether it
  // freed anything.
  bool ReleaseIfEmpty();
  size_t SlotCapacity() const { return entries_.capacity(); }

  bool IsQueued(EventHandle handle) const;
  WorkEvent Get(EventHandle handle) const;  // handle must be queued

  size_t size() const { return size_; }
  bool empty() const { return size_ == 0; }
  size_t QueueSize(EventType type, int dim) const { return queue_size_[QueueIndex(type, dim)]; }
  // Radius bucket of the largest pending event over all queues (for progress);
  // 0 when empty.
  double LargestPendingRadius() const;

  struct Stats {
    std::array<uint64_t, kNumEventTypes> pushed{};
    std::array<uint64_t, kNumEventTypes> popped{};
    std::array<uint64_t, kNumEventTypes> stale{};
    // By RemoveObjectEvent, per type: events whose object died, removed
    // before they were popped (they would have been stale).
    std::array<uint64_t, kNumEventTypes> removed_dead{};
    uint64_t rejected = 0;
    uint64_t decrease_size = 0;
    uint64_t increase_size = 0;
    // Empty buckets stepped over by Dequeue's cursor plus buckets skipped by
    // DecreaseSize: Lemmas 30–31 say O(1) per operation.
    uint64_t buckets_walked = 0;
    uint64_t max_walk_one_op = 0;
  };
  const Stats& stats() const { return stats_; }

  // Checks every list's links, sizes, cursors (no non-empty bucket above a
  // cursor). For tests; linear in size + buckets.
  bool Validate() const;

 private:
  static constexpr uint32_t kNil = 0xFFFFFFFFu;
  // A queued event and its list links: 40 bytes (64 while it held the
  // 24-byte centre, which the refiner rebuilds at pop; the queue's slots
  // were a quarter of cube --max-volume 1e-5's peak heap).
  struct Entry {
    double radius = 0;
    MeshId mesh;
    uint32_t object = 0;
    uint32_t event_generation = 0;  // WorkEvent::generation
    uint32_t prev = kNil, next = kNil;
    uint32_t generation = 0;  // the slot's: handles to a freed slot go stale
    EventType type = EventType::kSkinny;
    uint8_t dim = 3;
    int16_t queue = -1;  // -1: free slot
    int16_t bucket = 0;  // BucketOf's range [-1075, 1023]
    WorkEvent Event() const { return {type, dim, mesh, object, event_generation, radius}; }
    void Store(const WorkEvent& e) {
      type = e.type;
      dim = e.dim;
      mesh = e.mesh;
      object = e.object;
      event_generation = e.generation;
      radius = e.radius;
    }
  };
  static_assert(sizeof(Entry) == 40);
  // A queue's buckets come in chunks of 64, allocated when an event first
  // lands in one (a run touches a few dozen of the 2099 buckets; allocating
  // them all for twelve queues was 200 KB per job).
  static constexpr int kChunk = 64;
  static constexpr int kNumChunks = (kNumBuckets + kChunk - 1) / kChunk;
  struct Queue {
    // Per chunk: heads of its buckets in [0, kChunk), tails in [kChunk, 2·kChunk).
    std::array<std::unique_ptr<uint32_t[]>, kNumChunks> chunks;
    int cursor = -1;  // no non-empty bucket above it
    bool newest_first = false;  // pop a bucket's tail instead of its head
    uint32_t Head(int b) const {
      const uint32_t* c = chunks[b / kChunk].get();
      return c == nullptr ? kNil : c[b % kChunk];
    }
    uint32_t Tail(int b) const {
      const uint32_t* c = chunks[b / kChunk].get();
      return c == nullptr ? kNil : c[kChunk + b % kChunk];
    }
    // The chunk of bucket b, allocated (all kNil) if new.
    uint32_t* Chunk(int b);
  };

  void Link(uint32_t e, int queue, int bucket);
  void Unlink(uint32_t e);
  uint32_t PopFrom(int queue);
  void Free(uint32_t e);

  std::vector<Entry> entries_;
  uint32_t free_head_ = kNil;
  // Generation of new slots: above every generation handed out before the
  // last ReleaseIfEmpty (a slot's generation only grows while it exists).
  uint32_t first_generation_ = 0;
  std::array<Queue, kNumQueues> queues_;
  std::array<size_t, kNumQueues> queue_size_{};
  size_t size_ = 0;
  Stats stats_;
};

}  // namespace svrc::refine
