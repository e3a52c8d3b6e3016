// The recorder's reconciliation with the writers' counts (issue 20 section 6): what it
// reports missing is exactly what the writer wrote inside the window and never arrived.
#include <gtest/gtest.h>

#include <set>

#include "avs/bag/receipt_ledger.hpp"

namespace avs::bag {
namespace {

const WriterGid kWriter{1, 2, 3};
const WriterGid kOther{9};

/// The writer writes samples 1..n stamped i (its source time); a cut after sample i is (i, i).
WriterCut cut_after(std::int64_t i) {
  return {static_cast<std::uint64_t>(i), i};
}

TEST(ReceiptLedger, NothingMissingWhenEverySampleArrives) {
  ReceiptLedger ledger;
  for (std::int64_t i = 1; i <= 100; ++i) {
    ledger.received(kWriter, i);
    if (i % 10 == 0) ledger.reported(kWriter, cut_after(i));
  }
  const auto r = ledger.results().at(kWriter);
  ASSERT_TRUE(r.reconciled);
  EXPECT_EQ(r.window_start_ns, 10);
  EXPECT_EQ(r.window_end_ns, 100);
  EXPECT_EQ(r.expected, 90u);
  EXPECT_EQ(r.received_in_window, 90u);
  EXPECT_EQ(r.missing, 0u);
  EXPECT_EQ(r.received, 100u);
  EXPECT_EQ(r.reports, 10u);
}

TEST(ReceiptLedger, CountsExactlyTheSamplesThatNeverArrivedInsideTheWindow) {
  ReceiptLedger ledger;
  // Received from 15 on (the reader matched late), 40..52 and 77 lost, stopped after 93.
  const std::set<std::int64_t> lost = {40, 41, 42, 43, 44, 45, 46, 47, 48, 49, 50, 51, 52, 77};
  for (std::int64_t i = 1; i <= 100; ++i) {
    if (i >= 15 && i <= 93 && lost.count(i) == 0) ledger.received(kWriter, i);
    // Reports every 10 samples; the first two name samples the recorder never had.
    if (i % 10 == 0) ledger.reported(kWriter, cut_after(i));
  }
  const auto r = ledger.results().at(kWriter);
  ASSERT_TRUE(r.reconciled);
  EXPECT_EQ(r.window_start_ns, 20) << "the first cut whose last sample was received";
  EXPECT_EQ(r.window_end_ns, 90) << "the latest such cut";
  EXPECT_EQ(r.expected, 70u);
  EXPECT_EQ(r.missing, lost.size());
  EXPECT_EQ(r.received_in_window, 70u - lost.size());
  // A cut naming a lost sample (50) anchors nothing.
}

TEST(ReceiptLedger, ACutThatArrivesBeforeItsLastSampleAnchorsWhenTheSampleComes) {
  ReceiptLedger ledger;
  for (std::int64_t i = 1; i <= 5; ++i) ledger.received(kWriter, i);
  ledger.reported(kWriter, cut_after(5));  // start
  for (std::int64_t i = 6; i <= 9; ++i) ledger.received(kWriter, i);
  ledger.reported(kWriter, cut_after(10));  // sample 10 still in flight
  EXPECT_FALSE(ledger.results().at(kWriter).reconciled);
  ledger.received(kWriter, 11);  // out of order: 11 before 10
  ledger.received(kWriter, 10);
  const auto r = ledger.results().at(kWriter);
  ASSERT_TRUE(r.reconciled);
  EXPECT_EQ(r.window_end_ns, 10);
  EXPECT_EQ(r.expected, 5u);
  EXPECT_EQ(r.received_in_window, 5u) << "6..10; 11 is after the end anchor";
  EXPECT_EQ(r.missing, 0u);
}

TEST(ReceiptLedger, SamplesAfterTheEndAnchorAreOutsideTheWindow) {
  ReceiptLedger ledger;
  for (std::int64_t i = 1; i <= 30; ++i) {
    if (i != 25 && i != 27) ledger.received(kWriter, i);
    if (i == 10 || i == 20) ledger.reported(kWriter, cut_after(i));
  }
  const auto r = ledger.results().at(kWriter);
  ASSERT_TRUE(r.reconciled);
  EXPECT_EQ(r.expected, 10u);
  EXPECT_EQ(r.missing, 0u) << "25 and 27 were lost after the last cut: not counted";
}

TEST(ReceiptLedger, AWriterWithoutTwoAnchoredCutsIsNotReconciled) {
  ReceiptLedger ledger;
  for (std::int64_t i = 1; i <= 20; ++i) ledger.received(kOther, i);  // never reports
  for (std::int64_t i = 1; i <= 20; ++i) ledger.received(kWriter, i);
  ledger.reported(kWriter, cut_after(10));
  ledger.reported(kWriter, cut_after(10));  // no newer cut
  const auto results = ledger.results();
  EXPECT_FALSE(results.at(kOther).reconciled);
  EXPECT_EQ(results.at(kOther).received, 20u);
  EXPECT_FALSE(results.at(kWriter).reconciled);
  EXPECT_EQ(ledger.reports(kWriter), 2u);
  EXPECT_EQ(ledger.reports(kOther), 0u);
}

TEST(ReceiptLedger, WritersAreReconciledSeparately) {
  ReceiptLedger ledger;
  for (std::int64_t i = 1; i <= 50; ++i) {
    ledger.received(kWriter, i);
    if (i % 3 != 0) ledger.received(kOther, 1000 + i);
    if (i % 10 == 0) {
      ledger.reported(kWriter, cut_after(i));
      ledger.reported(kOther, {static_cast<std::uint64_t>(i), 1000 + i});
    }
  }
  const auto results = ledger.results();
  EXPECT_EQ(results.at(kWriter).missing, 0u);
  // kOther: window (1010, 1050]: 40 written, every third (1012, ..., 1050 minus 1050? 50 % 3
  // != 0) lost: 12, 15, ..., 48 -> 13 samples.
  EXPECT_EQ(results.at(kOther).expected, 40u);
  EXPECT_EQ(results.at(kOther).missing, 13u);
}

}  // namespace
}  // namespace avs::bag
