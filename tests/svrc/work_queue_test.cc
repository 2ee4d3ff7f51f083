// Tests of the SVRC work queues (thesis Figure 3.11, Lemmas 30–31).
#include "core/svrc/work_queue.h"

#include <cmath>
#include <random>
#include <vector>

#include "gtest/gtest.h"

namespace svrc::refine {
namespace {

WorkEvent Ev(EventType type, int dim, double r, uint32_t object = 0, uint32_t gen = 0) {
  WorkEvent e;
  e.type = type;
  e.dim = static_cast<uint8_t>(dim);
  e.mesh = MeshId(0);
  e.radius = r;
  e.object = object;
  e.generation = gen;
  return e;
}

// Pops every event; their objects in pop order.
std::vector<uint32_t> Drain(WorkQueues& q) {
  std::vector<uint32_t> order;
  while (auto e = q.Dequeue()) order.push_back(e->object);
  return order;
}

TEST(WorkQueueTest, BucketIsFloorLog2) {
  EXPECT_EQ(WorkQueues::BucketOf(1.0) + WorkQueues::kMinExp, 0);
  EXPECT_EQ(WorkQueues::BucketOf(1.999) + WorkQueues::kMinExp, 0);
  EXPECT_EQ(WorkQueues::BucketOf(2.0) + WorkQueues::kMinExp, 1);
  EXPECT_EQ(WorkQueues::BucketOf(0.5) + WorkQueues::kMinExp, -1);
  EXPECT_EQ(WorkQueues::BucketOf(std::nextafter(0.5, 0.0)) + WorkQueues::kMinExp, -2);
  EXPECT_EQ(WorkQueues::BucketOf(0.0), 0);
  EXPECT_EQ(WorkQueues::BucketOf(5e-324), 1);  // smallest subnormal: ilogb = -1074
  EXPECT_EQ(WorkQueues::BucketOf(1.7e308), WorkQueues::kNumBuckets - 1);
}

// Figure 3.11: Skinny 1→3, then Encroached 2→1, then Unresolved 3→1, then
// Collar 2→3 — regardless of radius across queues.
TEST(WorkQueueTest, GlobalPriorityOrder) {
  WorkQueues q;
  using T = EventType;
  // Pushed in scrambled order; radii chosen so that "largest first" would give
  // a different order if priority were by radius.
  q.Enqueue(Ev(T::kCollar, 3, 100, 1));
  q.Enqueue(Ev(T::kUnresolved, 1, 100, 2));
  q.Enqueue(Ev(T::kSkinny, 3, 1, 3));
  q.Enqueue(Ev(T::kEncroached, 1, 100, 4));
  q.Enqueue(Ev(T::kCollar, 2, 1, 5));
  q.Enqueue(Ev(T::kUnresolved, 3, 1, 6));
  q.Enqueue(Ev(T::kSkinny, 1, 0.001, 7));
  q.Enqueue(Ev(T::kEncroached, 2, 0.001, 8));
  q.Enqueue(Ev(T::kUnresolved, 2, 1e9, 9));
  q.Enqueue(Ev(T::kSkinny, 2, 1e9, 10));
  ASSERT_TRUE(q.Validate());
  EXPECT_EQ(Drain(q), (std::vector<uint32_t>{7, 10, 3, 8, 4, 6, 9, 2, 5, 1}));
  EXPECT_TRUE(q.empty());
}

TEST(WorkQueueTest, RejectsEventsWithoutAQueue) {
  WorkQueues q;
  EXPECT_FALSE(q.Enqueue(Ev(EventType::kCollar, 1, 1)).valid());      // Collar₁: via Unresolved₁
  EXPECT_FALSE(q.Enqueue(Ev(EventType::kEncroached, 3, 1)).valid());  // no 3D protective balls
  EXPECT_FALSE(q.Enqueue(Ev(EventType::kSkinny, 0, 1)).valid());
  EXPECT_FALSE(q.Enqueue(Ev(EventType::kSkinny, 2, -1)).valid());
  EXPECT_FALSE(q.Enqueue(Ev(EventType::kSkinny, 2, NAN)).valid());
  EXPECT_FALSE(q.Enqueue(Ev(EventType::kSkinny, 2, INFINITY)).valid());
  EXPECT_EQ(q.stats().rejected, 6u);
  EXPECT_TRUE(q.empty());
}

// Inside one queue: largest bucket first, FIFO inside a bucket (not by exact
// radius: the thesis only needs approximately-largest-first, §5.1.2).
TEST(WorkQueueTest, LargestBucketFirstFifoInsideBucket) {
  WorkQueues q;
  q.Enqueue(Ev(EventType::kSkinny, 3, 1.0, 1));
  q.Enqueue(Ev(EventType::kSkinny, 3, 8.5, 2));
  q.Enqueue(Ev(EventType::kSkinny, 3, 1.9, 3));  // same bucket as 1: after it
  q.Enqueue(Ev(EventType::kSkinny, 3, 0.25, 4));
  q.Enqueue(Ev(EventType::kSkinny, 3, 15.9, 5));  // same bucket as 8.5: after it
  q.Enqueue(Ev(EventType::kSkinny, 3, 1.5, 6));
  EXPECT_EQ(Drain(q), (std::vector<uint32_t>{2, 5, 1, 3, 6, 4}));
}

// SetNewestFirst: the same buckets, largest first, but a bucket of that queue
// is served newest first (LIFO); the other queues stay FIFO. An event moved by
// DecreaseSize is the newest of its new bucket.
TEST(WorkQueueTest, NewestFirstQueueIsLifoInsideBucket) {
  WorkQueues q;
  q.SetNewestFirst(EventType::kSkinny, 3, true);
  EXPECT_TRUE(q.NewestFirst(EventType::kSkinny, 3));
  EXPECT_FALSE(q.NewestFirst(EventType::kSkinny, 2));
  q.Enqueue(Ev(EventType::kSkinny, 3, 1.0, 1));
  q.Enqueue(Ev(EventType::kSkinny, 3, 8.5, 2));
  q.Enqueue(Ev(EventType::kSkinny, 3, 1.9, 3));
  q.Enqueue(Ev(EventType::kSkinny, 3, 0.25, 4));
  q.Enqueue(Ev(EventType::kSkinny, 3, 15.9, 5));
  const EventHandle h = q.Enqueue(Ev(EventType::kSkinny, 3, 9.0, 6));
  q.Enqueue(Ev(EventType::kSkinny, 3, 1.5, 7));
  q.DecreaseSize(h, 1.2);  // 6 leaves bucket 3 for bucket 0, after 7
  // A FIFO queue of lower priority, pushed in the same order.
  q.Enqueue(Ev(EventType::kUnresolved, 3, 1.0, 11));
  q.Enqueue(Ev(EventType::kUnresolved, 3, 1.9, 13));
  q.Enqueue(Ev(EventType::kUnresolved, 3, 1.5, 17));
  ASSERT_TRUE(q.Validate());
  EXPECT_EQ(Drain(q), (std::vector<uint32_t>{5, 2, 6, 7, 3, 1, 4, 11, 13, 17}));
  // Switched back: FIFO again.
  q.SetNewestFirst(EventType::kSkinny, 3, false);
  q.Enqueue(Ev(EventType::kSkinny, 3, 1.0, 21));
  q.Enqueue(Ev(EventType::kSkinny, 3, 1.5, 22));
  EXPECT_EQ(q.Dequeue()->object, 21u);
  EXPECT_EQ(q.Dequeue()->object, 22u);
}

// ReleaseIfEmpty frees the event slots only when nothing is queued, and a
// handle from before never matches an event made after (the slots restart
// at a generation above every one handed out).
TEST(WorkQueueTest, ReleaseIfEmptyKeepsOldHandlesStale) {
  WorkQueues q;
  std::vector<EventHandle> old;
  for (uint32_t i = 0; i < 100; ++i) old.push_back(q.Enqueue(Ev(EventType::kSkinny, 3, 1.0 + i, i)));
  q.Remove(old[5]);
  EXPECT_FALSE(q.ReleaseIfEmpty());  // 99 queued
  EXPECT_TRUE(q.IsQueued(old[6]));
  while (q.Dequeue()) {
  }
  EXPECT_GE(q.SlotCapacity(), 100u);
  EXPECT_TRUE(q.ReleaseIfEmpty());
  EXPECT_EQ(q.SlotCapacity(), 0u);
  EXPECT_FALSE(q.ReleaseIfEmpty());  // nothing left to free
  // The same slots again, a few pushed and popped twice over.
  std::vector<EventHandle> fresh;
  for (uint32_t i = 0; i < 100; ++i) fresh.push_back(q.Enqueue(Ev(EventType::kUnresolved, 3, 2.0, 1000 + i)));
  for (const EventHandle& h : old) {
    EXPECT_FALSE(q.IsQueued(h));
    q.Remove(h);                     // a no-op on a stale handle
    q.DecreaseSize(h, 0.001);        // likewise
  }
  ASSERT_TRUE(q.Validate());
  EXPECT_EQ(q.size(), 100u);
  for (const EventHandle& h : fresh) EXPECT_TRUE(q.IsQueued(h));
  std::vector<uint32_t> order = Drain(q);
  ASSERT_EQ(order.size(), 100u);
  for (uint32_t i = 0; i < 100; ++i) EXPECT_EQ(order[i], 1000 + i);  // FIFO, none moved or removed
}

TEST(WorkQueueTest, StaleEventsDroppedOnPopAndCounted) {
  WorkQueues q;
  std::vector<uint32_t> generation = {0, 0, 0, 0};
  for (uint32_t i = 0; i < 4; ++i) q.Enqueue(Ev(EventType::kUnresolved, 3, 1.0 + i, i, 0));
  generation[3] = 1;  // cell 3 changed: its event is stale
  generation[1] = 5;
  auto live = [&](const WorkEvent& e) { return generation[e.object] == e.generation; };
  auto a = q.DequeueLive(live);
  ASSERT_TRUE(a);
  EXPECT_EQ(a->object, 2u);  // 3 (largest) was stale
  auto b = q.DequeueLive(live);
  ASSERT_TRUE(b);
  EXPECT_EQ(b->object, 0u);  // 1 (bucket 1, ahead of 0's bucket 0) was stale
  EXPECT_FALSE(q.DequeueLive(live));
  EXPECT_EQ(q.stats().stale[static_cast<int>(EventType::kUnresolved)], 2u);
  EXPECT_EQ(q.stats().popped[static_cast<int>(EventType::kUnresolved)], 4u);
}

TEST(WorkQueueTest, HandlesGoStaleAfterPopAndSlotReuse) {
  WorkQueues q;
  EventHandle h = q.Enqueue(Ev(EventType::kSkinny, 3, 4.0, 7));
  ASSERT_TRUE(q.IsQueued(h));
  EXPECT_EQ(q.Get(h).object, 7u);
  ASSERT_TRUE(q.Dequeue());
  EXPECT_FALSE(q.IsQueued(h));
  EventHandle h2 = q.Enqueue(Ev(EventType::kSkinny, 3, 4.0, 8));  // reuses the slot
  EXPECT_EQ(h2.id, h.id);
  EXPECT_FALSE(q.IsQueued(h));
  q.DecreaseSize(h, 0.1);  // stale handle: no effect on the new occupant
  q.Remove(h);
  ASSERT_TRUE(q.IsQueued(h2));
  EXPECT_EQ(q.Get(h2).radius, 4.0);
  q.Remove(h2);
  EXPECT_TRUE(q.empty());
  EXPECT_TRUE(q.Validate());
}

// Lemma 30: DecreaseSize moves the event to its new bucket, behind the events
// already there, and costs the number of buckets between.
// RemoveObjectEvent takes a slot number only: it removes the event there
// when that event is the named object's, and nothing once the slot was
// popped, or freed and reused by another object's event.
TEST(WorkQueueTest, RemoveObjectEventRemovesOnlyThatObjectsEvent) {
  WorkQueues q;
  const EventHandle a = q.Enqueue(Ev(EventType::kSkinny, 3, 1.0, 10));
  const EventHandle b = q.Enqueue(Ev(EventType::kSkinny, 3, 1.0, 11));
  const EventHandle c = q.Enqueue(Ev(EventType::kSkinny, 3, 4.0, 12));
  ASSERT_TRUE(a.valid() && b.valid() && c.valid());
  EXPECT_FALSE(q.RemoveObjectEvent(b.id, MeshId(0), 10));  // b's slot holds 11's event
  EXPECT_FALSE(q.RemoveObjectEvent(b.id, MeshId(1), 11));  // another mesh
  EXPECT_FALSE(q.RemoveObjectEvent(EventId(), MeshId(0), 11));
  EXPECT_TRUE(q.RemoveObjectEvent(b.id, MeshId(0), 11));
  EXPECT_FALSE(q.IsQueued(b));
  EXPECT_FALSE(q.RemoveObjectEvent(b.id, MeshId(0), 11));  // already gone
  EXPECT_EQ(q.size(), 2u);
  EXPECT_EQ(q.stats().removed_dead[static_cast<int>(EventType::kSkinny)], 1u);
  // b's slot reused by object 13: 11's removal must not take it.
  const EventHandle d = q.Enqueue(Ev(EventType::kSkinny, 3, 1.0, 13));
  ASSERT_EQ(d.id, b.id);
  EXPECT_FALSE(q.RemoveObjectEvent(d.id, MeshId(0), 11));
  EXPECT_TRUE(q.Validate());
  EXPECT_EQ(Drain(q), (std::vector<uint32_t>{12, 10, 13}));  // the rest keep their order
  EXPECT_FALSE(q.RemoveObjectEvent(c.id, MeshId(0), 12));    // popped
}

TEST(WorkQueueTest, DecreaseSizeMovesBucketAndCountsWalk) {
  WorkQueues q;
  EventHandle big = q.Enqueue(Ev(EventType::kSkinny, 3, 64.0, 1));   // bucket 6
  q.Enqueue(Ev(EventType::kSkinny, 3, 4.0, 2));                        // bucket 2
  q.Enqueue(Ev(EventType::kSkinny, 3, 16.0, 3));                       // bucket 4
  const uint64_t walked0 = q.stats().buckets_walked;
  q.DecreaseSize(big, 5.0);  // bucket 6 → 2: walks 4
  EXPECT_EQ(q.stats().buckets_walked - walked0, 4u);
  q.DecreaseSize(big, 100.0);  // growing is ignored
  EXPECT_EQ(q.Get(big).radius, 5.0);
  q.DecreaseSize(big, 4.5);  // same bucket: keeps its place
  EXPECT_TRUE(q.Validate());
  std::vector<uint32_t> order;
  while (auto e = q.Dequeue()) order.push_back(e->object);
  EXPECT_EQ(order, (std::vector<uint32_t>{3, 2, 1}));
  EXPECT_EQ(q.stats().decrease_size, 2u);
}

// Lemma 31 setting: radii shrink by a bounded factor between consecutive
// operations, so the buckets walked per operation stay O(1) no matter how many
// events there are.
TEST(WorkQueueTest, BucketWalkIsConstantPerOperationUnderBoundedShrink) {
  WorkQueues q;
  std::mt19937_64 rng(42);
  std::uniform_real_distribution<double> factor(0.3, 1.0);
  double r = 1.0;
  uint64_t ops = 0;
  for (int round = 0; round < 2000; ++round) {
    // Destroying an event of size ~r creates a few events of size ≳ r/4.
    for (int k = 0; k < 3; ++k) {
      q.Enqueue(Ev(EventType::kSkinny, 3, r * factor(rng), round));
      ++ops;
    }
    auto e = q.Dequeue();
    ASSERT_TRUE(e);
    ++ops;
    r = e->radius;
  }
  EXPECT_LE(q.stats().max_walk_one_op, 3u);
  EXPECT_LE(q.stats().buckets_walked, ops);
  EXPECT_TRUE(q.Validate());
}

// Same pushes → same pops, independent of anything but push order.
TEST(WorkQueueTest, Deterministic) {
  auto run = [] {
    WorkQueues q;
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> rad(1e-6, 1e3);
    std::vector<uint32_t> out;
    for (uint32_t i = 0; i < 5000; ++i) {
      const int t = static_cast<int>(rng() % 4);
      int dim = 1 + static_cast<int>(rng() % 3);
      if (t == 1 && dim == 3) dim = 2;
      if (t == 3 && dim == 1) dim = 2;
      q.Enqueue(Ev(static_cast<EventType>(t), dim, rad(rng), i));
      if (i % 3 == 0) out.push_back(q.Dequeue()->object);
    }
    while (auto e = q.Dequeue()) out.push_back(e->object);
    return out;
  };
  const auto a = run();
  EXPECT_EQ(a.size(), 5000u);
  EXPECT_EQ(a, run());
}

TEST(WorkQueueTest, LargestPendingRadiusIsBucketFloor) {
  WorkQueues q;
  EXPECT_EQ(q.LargestPendingRadius(), 0.0);
  q.Enqueue(Ev(EventType::kUnresolved, 3, 3.0));
  q.Enqueue(Ev(EventType::kSkinny, 2, 0.7));
  EXPECT_EQ(q.LargestPendingRadius(), 2.0);
  EXPECT_EQ(q.QueueSize(EventType::kSkinny, 2), 1u);
}

}  // namespace
}  // namespace svrc::refine
