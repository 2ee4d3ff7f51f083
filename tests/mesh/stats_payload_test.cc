// A failed run's counters ride on its status (core/mesh/stats_payload.h):
// exact round trip, kept through re-worded errors, ignored on OK.
#include "core/mesh/stats_payload.h"

#include <cmath>
#include <limits>

#include "absl/strings/cord.h"
#include "gtest/gtest.h"

namespace svrc::mesh {
namespace {

TEST(StatsPayload, RoundTripsEveryCounterBitExactInOrder) {
  MeshStats stats;
  stats.Set("svrc.vertices", 9261);
  stats.Set("svrc.third", 1.0 / 3.0);
  stats.Set("svrc.tiny", 4.9406564584124654e-324);  // the smallest subnormal
  stats.Set("svrc.huge", 1.8446744073709552e19);
  stats.Set("svrc.negative", -0.1);
  absl::Status st = absl::DeadlineExceededError("job deadline exceeded");
  AttachStats(stats, &st);
  const std::optional<MeshStats> back = StatsOf(st);
  ASSERT_TRUE(back.has_value());
  ASSERT_EQ(back->counters.size(), stats.counters.size());
  for (size_t i = 0; i < stats.counters.size(); ++i) {
    EXPECT_EQ(back->counters[i].first, stats.counters[i].first);
    EXPECT_EQ(std::signbit(back->counters[i].second), std::signbit(stats.counters[i].second));
    EXPECT_EQ(back->counters[i].second, stats.counters[i].second) << stats.counters[i].first;
  }
  EXPECT_EQ(st.code(), absl::StatusCode::kDeadlineExceeded);
  EXPECT_EQ(st.message(), "job deadline exceeded");
}

TEST(StatsPayload, RewrapKeepsTheCountersAndTakesTheNewWords) {
  MeshStats stats;
  stats.Set("svrc.max_yield_chain", 76);
  absl::Status inner = absl::ResourceExhaustedError("vertex budget reached");
  AttachStats(stats, &inner);
  const absl::Status outer = Rewrap(absl::StatusCode::kFailedPrecondition, "crease: did not finish", inner);
  EXPECT_EQ(outer.code(), absl::StatusCode::kFailedPrecondition);
  EXPECT_EQ(outer.message(), "crease: did not finish");
  const std::optional<MeshStats> back = StatsOf(outer);
  ASSERT_TRUE(back.has_value());
  EXPECT_EQ(back->Get("svrc.max_yield_chain", -1), 76);
}

TEST(StatsPayload, NothingOnOkOrWithoutAPayload) {
  MeshStats stats;
  stats.Set("a", 1);
  absl::Status ok = absl::OkStatus();
  AttachStats(stats, &ok);
  EXPECT_FALSE(StatsOf(ok).has_value());
  EXPECT_FALSE(StatsOf(absl::InternalError("x")).has_value());
  // An empty stats list is a payload with no counters, not "no payload".
  absl::Status empty = absl::InternalError("x");
  AttachStats(MeshStats{}, &empty);
  ASSERT_TRUE(StatsOf(empty).has_value());
  EXPECT_TRUE(StatsOf(empty)->counters.empty());
}

TEST(StatsPayload, MalformedPayloadsAreRefused) {
  for (const char* text : {"no-tab-here\n", "\t1\n", "name\tnot-a-number\n", "name\t1.5x\n", "name\t\n"}) {
    absl::Status st = absl::InternalError("x");
    st.SetPayload(kStatsPayloadUrl, absl::Cord(text));
    EXPECT_FALSE(StatsOf(st).has_value()) << text;
  }
}

}  // namespace
}  // namespace svrc::mesh
