// Copyright wild_mvs authors. The fusion node's keyframe ledger: keyframes
// announced by a selector and never reconstructed are named missing once
// missing_after has passed, a second first reconstruction is named done
// twice, redos are not, and memory stays bounded; on an injected clock.
#include <gtest/gtest.h>

#include "wild_mvs/core/error.h"
#include "wild_mvs/stream/keyframe_ledger.h"

namespace wild_mvs {
namespace {

struct FakeClock {
  double now = 100.0;
  KeyframeLedger::ClockFn Fn() {
    return [this] { return now; };
  }
};

constexpr uint64_t kSession = 1700000000000000000ull;

TEST(KeyframeLedger, NamesMissingAndTwiceDoneKeyframes) {
  FakeClock clock;
  KeyframeLedgerOptions o;
  o.missing_after = 10.0;
  KeyframeLedger ledger(o, clock.Fn());
  for (uint64_t i = 0; i < 5; ++i) ledger.Announce(kSession, kSession + i);
  ledger.Announce(kSession, kSession + 1);  // repeats are ignored
  EXPECT_TRUE(ledger.Done(kSession, kSession + 0, 0));
  EXPECT_TRUE(ledger.Done(kSession, kSession + 1, 0));
  EXPECT_TRUE(ledger.Done(kSession, kSession + 1, 1));   // a redo: fine
  EXPECT_FALSE(ledger.Done(kSession, kSession + 0, 0));  // done twice
  EXPECT_TRUE(ledger.Done(kSession, kSession + 3, 0));
  // Not yet missing: within missing_after of the announcement.
  KeyframeLedger::Report r = ledger.Summarize(8);
  EXPECT_EQ(r.announced, 5u);
  EXPECT_EQ(r.done, 3u);
  EXPECT_EQ(r.missing, 0u);
  EXPECT_EQ(r.twice, 1u);
  ASSERT_EQ(r.twice_keys.size(), 1u);
  EXPECT_EQ(r.twice_keys[0].second, kSession + 0);
  clock.now += 10.5;
  r = ledger.Summarize(8);
  EXPECT_EQ(r.missing, 2u);
  ASSERT_EQ(r.missing_keys.size(), 2u);
  EXPECT_EQ(r.missing_keys[0].second, kSession + 2);
  EXPECT_EQ(r.missing_keys[1].second, kSession + 4);
  // A late depth view is no longer missing.
  EXPECT_TRUE(ledger.Done(kSession, kSession + 2, 0));
  r = ledger.Summarize(1);
  EXPECT_EQ(r.missing, 1u);
  EXPECT_EQ(r.missing_keys.size(), 1u);
  // Views of keyframes never announced (no selector) count for twice only.
  EXPECT_TRUE(ledger.Done(kSession + 9, 5, 0));
  EXPECT_FALSE(ledger.Done(kSession + 9, 5, 0));
  r = ledger.Summarize(8);
  EXPECT_EQ(r.twice, 2u);
  EXPECT_EQ(r.missing, 1u);
  ledger.Clear();
  r = ledger.Summarize(8);
  EXPECT_EQ(r.announced + r.done + r.missing + r.twice, 0u);
}

TEST(KeyframeLedger, SessionsAreKeptApart) {
  FakeClock clock;
  KeyframeLedger ledger(KeyframeLedgerOptions(), clock.Fn());
  // A bag played twice: the same stamps in two sessions.
  ledger.Announce(1, 10);
  ledger.Announce(2, 10);
  EXPECT_TRUE(ledger.Done(1, 10, 0));
  EXPECT_TRUE(ledger.Done(2, 10, 0));
  EXPECT_EQ(ledger.Summarize(4).twice, 0u);
}

TEST(KeyframeLedger, MemoryIsBounded) {
  FakeClock clock;
  KeyframeLedgerOptions o;
  o.max_keyframes = 100;
  o.missing_after = 1.0;
  KeyframeLedger ledger(o, clock.Fn());
  for (uint64_t i = 0; i < 1000; ++i) ledger.Announce(kSession, i);
  clock.now += 2;
  const KeyframeLedger::Report r = ledger.Summarize(4);
  EXPECT_EQ(r.announced, 100u);
  EXPECT_EQ(r.missing, 100u);
  EXPECT_EQ(r.missing_keys.front().second, 900u);  // the newest are kept
}

TEST(KeyframeLedger, OptionsAreChecked) {
  KeyframeLedgerOptions o;
  o.missing_after = 0;
  EXPECT_THROW(KeyframeLedger l(o), Error);
  o = KeyframeLedgerOptions();
  o.max_keyframes = 0;
  EXPECT_THROW(KeyframeLedger l(o), Error);
}

}  // namespace
}  // namespace wild_mvs
