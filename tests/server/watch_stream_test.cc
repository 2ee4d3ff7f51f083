// WatchStream (the flow control of a WatchJob stream, server/watch_stream.h):
// coalescing of unsent snapshots, finish after the terminal one, close; and
// the same from three threads (a producer standing in for the job manager's
// workers, a transport standing in for gRPC, a canceller) so that the TSan
// stage checks it: never two writes in flight, written sequences increase,
// the call is finished exactly once and nothing is written after that.
#include "server/watch_stream.h"

#include <atomic>
#include <condition_variable>
#include <deque>
#include <mutex>
#include <random>
#include <thread>
#include <vector>

#include "gtest/gtest.h"

namespace svrc::server {
namespace {

using Action = WatchStream::Action;

// A few cycles of busy waiting that the compiler keeps.
inline void Pause() {
  static std::atomic<int> sink{0};
  sink.fetch_add(1, std::memory_order_relaxed);
}

v1::JobEvent Event(uint64_t seq, v1::JobState state = v1::RUNNING) {
  v1::JobEvent e;
  e.set_sequence(seq);
  e.mutable_job()->set_state(state);
  return e;
}

TEST(WatchStreamTest, OneWriteInFlightAndTheNewestUnsentSnapshotNext) {
  WatchStream s;
  EXPECT_EQ(s.Offer(Event(1, v1::QUEUED)), Action::kWrite);
  EXPECT_EQ(s.in_flight().sequence(), 1u);
  EXPECT_EQ(s.Offer(Event(2)), Action::kNone);  // 1 is still being written
  EXPECT_EQ(s.Offer(Event(3)), Action::kNone);  // replaces 2
  EXPECT_EQ(s.in_flight().sequence(), 1u);
  EXPECT_EQ(s.WriteDone(), Action::kWrite);
  EXPECT_EQ(s.in_flight().sequence(), 3u);
  EXPECT_EQ(s.WriteDone(), Action::kNone);  // idle
  EXPECT_EQ(s.Offer(Event(4)), Action::kWrite);
  EXPECT_EQ(s.in_flight().sequence(), 4u);
}

TEST(WatchStreamTest, FinishesAfterTheTerminalSnapshotIsWritten) {
  WatchStream s;
  EXPECT_EQ(s.Offer(Event(1)), Action::kWrite);
  EXPECT_EQ(s.Offer(Event(2, v1::SUCCEEDED)), Action::kNone);  // pending
  EXPECT_EQ(s.Offer(Event(3, v1::SUCCEEDED)), Action::kNone);  // after the end: dropped
  EXPECT_EQ(s.WriteDone(), Action::kWrite);
  EXPECT_EQ(s.in_flight().sequence(), 2u);
  EXPECT_EQ(s.in_flight().job().state(), v1::SUCCEEDED);
  EXPECT_EQ(s.WriteDone(), Action::kFinish);
  EXPECT_FALSE(s.Close());  // already finished
  EXPECT_EQ(s.Offer(Event(4)), Action::kNone);
}

TEST(WatchStreamTest, AClosedStreamWritesNothingMore) {
  WatchStream s;
  EXPECT_EQ(s.Offer(Event(1)), Action::kWrite);
  EXPECT_EQ(s.Offer(Event(2)), Action::kNone);
  EXPECT_TRUE(s.Close());
  EXPECT_FALSE(s.Close());
  EXPECT_EQ(s.WriteDone(), Action::kNone);  // 2 is not written after the close
  EXPECT_EQ(s.Offer(Event(3, v1::SUCCEEDED)), Action::kNone);
}

// A fake transport: writes are started from any thread (Start), completed
// on the transport's own thread, which then calls WriteDone like gRPC's
// OnWriteDone does. Checks the gRPC rule of one outstanding write.
class FakeTransport {
 public:
  explicit FakeTransport(WatchStream* stream) : stream_(stream) {
    thread_ = std::thread([this] { Loop(); });
  }
  ~FakeTransport() {
    {
      std::scoped_lock lock(mu_);
      stop_ = true;
    }
    cv_.notify_all();
    thread_.join();
  }
  // StartWrite. Two outstanding writes abort a real server: gRPC's
  // grpc_call_start_batch answers GRPC_CALL_ERROR_TOO_MANY_OPERATIONS and
  // grpcpp asserts ("API misuse").
  void Start() {
    if (outstanding_.fetch_add(1) != 0) overlapping_writes_.fetch_add(1);
    if (finished_.load() > 0) writes_after_finish_.fetch_add(1);
    {
      std::scoped_lock lock(mu_);
      ++queued_;
    }
    cv_.notify_all();
  }
  void Finish() { finished_.fetch_add(1); }

  // Read on the test thread after the transport has gone quiet.
  std::vector<uint64_t> written() {
    std::scoped_lock lock(mu_);
    return written_;
  }
  bool last_was_terminal() {
    std::scoped_lock lock(mu_);
    return last_terminal_;
  }
  int finished() const { return finished_.load(); }
  int overlapping_writes() const { return overlapping_writes_.load(); }
  int writes_after_finish() const { return writes_after_finish_.load(); }
  // No write queued or being completed (the test's producers are done).
  bool Idle() {
    std::scoped_lock lock(mu_);
    return queued_ == 0 && !busy_;
  }

 private:
  void Loop() {
    std::minstd_rand rng(7);
    for (;;) {
      {
        std::unique_lock lock(mu_);
        cv_.wait(lock, [this] { return stop_ || queued_ > 0; });
        if (queued_ == 0) return;  // stop_
        --queued_;
        busy_ = true;
      }
      // "Serialize" the message: read in_flight() outside any lock, as gRPC does.
      const uint64_t seq = stream_->in_flight().sequence();
      const bool terminal = stream_->in_flight().job().state() == v1::SUCCEEDED;
      if (rng() % 4 == 0) std::this_thread::yield();
      {
        std::scoped_lock lock(mu_);
        written_.push_back(seq);
        last_terminal_ = terminal;
      }
      outstanding_.fetch_sub(1);
      switch (stream_->WriteDone()) {
        case Action::kWrite:
          Start();
          break;
        case Action::kFinish:
          Finish();
          break;
        case Action::kNone:
          break;
      }
      std::scoped_lock lock(mu_);
      busy_ = false;
    }
  }

  WatchStream* stream_;
  std::mutex mu_;
  std::condition_variable cv_;
  int queued_ = 0;     // guarded by mu_
  bool stop_ = false;  // guarded by mu_
  bool busy_ = false;  // guarded by mu_: a write is being completed
  std::vector<uint64_t> written_;  // guarded by mu_
  bool last_terminal_ = false;     // guarded by mu_
  std::atomic<int> outstanding_{0};
  std::atomic<int> overlapping_writes_{0};
  std::atomic<int> writes_after_finish_{0};
  std::atomic<int> finished_{0};
  std::thread thread_;
};

void WaitIdle(FakeTransport& t) {
  for (int i = 0; i < 20000 && !t.Idle(); ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
}

TEST(WatchStreamTest, ConcurrentOffersAndWriteCompletionsKeepOneWriteInFlight) {
  for (int round = 0; round < 20; ++round) {
    WatchStream stream;
    FakeTransport transport(&stream);
    constexpr uint64_t kEvents = 2000;
    std::thread producer([&] {
      std::minstd_rand rng(round);
      for (uint64_t seq = 1; seq <= kEvents; ++seq) {
        if (stream.Offer(Event(seq, seq == kEvents ? v1::SUCCEEDED : v1::RUNNING)) ==
            Action::kWrite) {
          transport.Start();
        }
        // Uneven pacing: bursts (offers coalesce while a write is in flight)
        // and pauses (the stream goes idle, so offers and write completions
        // race to start the next write).
        for (uint32_t spin = rng() % 2000; spin > 0; --spin) Pause();
      }
    });
    producer.join();
    WaitIdle(transport);
    ASSERT_EQ(transport.overlapping_writes(), 0) << "round " << round;
    ASSERT_EQ(transport.writes_after_finish(), 0) << "round " << round;
    EXPECT_EQ(transport.finished(), 1) << "round " << round;
    const std::vector<uint64_t> written = transport.written();
    ASSERT_FALSE(written.empty());
    for (size_t i = 1; i < written.size(); ++i) ASSERT_LT(written[i - 1], written[i]);
    EXPECT_EQ(written.back(), kEvents);  // the terminal snapshot is never coalesced away
    EXPECT_TRUE(transport.last_was_terminal());
  }
}

// The race that matters most: a snapshot offered while the only write in
// flight completes. Exactly one of Offer and WriteDone may start the next
// write (two outstanding writes abort the server, see FakeTransport::Start).
// Each iteration releases both calls at once from two threads.
TEST(WatchStreamTest, OfferRacingTheWriteCompletionStartsExactlyOneWrite) {
  WatchStream stream;
  ASSERT_EQ(stream.Offer(Event(1)), Action::kWrite);  // one write in flight
  constexpr int kIterations = 20000;
  std::atomic<int> go{0}, done{0};
  std::atomic<int> completer_started{0};
  // Spins (yielding now and then) so that both calls start within
  // nanoseconds of each other when the two threads have a core each.
  auto wait_for = [](const std::atomic<int>& counter, int value) {
    for (int spins = 0; counter.load() < value; ++spins) {
      if (spins % 4096 == 4095) std::this_thread::yield();
    }
  };
  std::thread completer([&] {
    for (int i = 1; i <= kIterations; ++i) {
      wait_for(go, i);
      if (stream.WriteDone() == Action::kWrite) completer_started.fetch_add(1);
      done.fetch_add(1);
    }
  });
  int bad_iterations = 0;
  int offer_started = 0;
  for (int i = 1; i <= kIterations; ++i) {
    const int before = completer_started.load() + offer_started;
    go.store(i);
    if (stream.Offer(Event(i + 1)) == Action::kWrite) ++offer_started;
    wait_for(done, i);
    if (completer_started.load() + offer_started - before != 1) ++bad_iterations;
  }
  completer.join();
  EXPECT_EQ(bad_iterations, 0) << "iterations that started 0 or 2 writes";
  EXPECT_EQ(completer_started.load() + offer_started, kIterations);
}

TEST(WatchStreamTest, CloseRacingOffersAndWritesFinishesTheCallOnce) {
  for (int round = 0; round < 20; ++round) {
    WatchStream stream;
    FakeTransport transport(&stream);
    std::atomic<bool> closed_first{false};
    std::thread producer([&] {
      for (uint64_t seq = 1; seq <= 2000; ++seq) {
        if (stream.Offer(Event(seq, seq == 2000 ? v1::SUCCEEDED : v1::RUNNING)) == Action::kWrite) {
          transport.Start();
        }
      }
    });
    std::thread canceller([&] {
      std::this_thread::sleep_for(std::chrono::microseconds(50 * round));
      if (stream.Close()) {
        closed_first = true;
        transport.Finish();
      }
    });
    producer.join();
    canceller.join();
    WaitIdle(transport);
    EXPECT_EQ(transport.finished(), 1) << "round " << round;  // by Close or by kFinish, not both
    ASSERT_EQ(transport.overlapping_writes(), 0) << "round " << round;
    const std::vector<uint64_t> written = transport.written();
    for (size_t i = 1; i < written.size(); ++i) ASSERT_LT(written[i - 1], written[i]);
    if (!closed_first) {
      EXPECT_TRUE(transport.last_was_terminal());
    }
  }
}

}  // namespace
}  // namespace svrc::server
