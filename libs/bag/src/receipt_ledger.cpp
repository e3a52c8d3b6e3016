#include "avs/bag/receipt_ledger.hpp"

#include <algorithm>

namespace avs::bag {

namespace {

// Receipts remembered per writer: at a 0.1 s report period this covers the samples since the
// last report up to 650 kHz. Older receipts only ever matter for cuts that arrive too late.
constexpr std::size_t kRecentReceipts = 1u << 16;
constexpr std::size_t kPendingCuts = 64;

}  // namespace

void ReceiptLedger::received(const WriterGid& writer, std::int64_t source_time_ns) {
  Writer& w = writers_[writer];
  ++w.received;
  w.newest = std::max(w.newest, source_time_ns);
  if (w.start && source_time_ns > w.start->last_source_time_ns) ++w.after_start;
  w.recent.push_back(source_time_ns);
  w.recent_set.insert(source_time_ns);
  if (w.recent.size() > kRecentReceipts) {
    w.recent_set.erase(w.recent.front());
    w.recent.pop_front();
  }
  for (auto it = w.pending.begin(); it != w.pending.end(); ++it) {
    if (it->last_source_time_ns != source_time_ns) continue;
    const WriterCut cut = *it;
    w.pending.erase(it);
    anchor(w, cut);
    break;
  }
}

void ReceiptLedger::reported(const WriterGid& writer, const WriterCut& cut) {
  Writer& w = writers_[writer];
  ++w.reports;
  if (cut.published == 0) return;
  if (w.recent_set.count(cut.last_source_time_ns) != 0) {
    anchor(w, cut);
    return;
  }
  // Its last sample may still come (reports and samples travel on different writers).
  w.pending.push_back(cut);
  if (w.pending.size() > kPendingCuts) w.pending.erase(w.pending.begin());
}

void ReceiptLedger::anchor(Writer& w, const WriterCut& cut) {
  if (!w.start) {
    w.start = cut;
    w.after_start = static_cast<std::uint64_t>(
        std::count_if(w.recent.begin(), w.recent.end(),
                      [&](std::int64_t t) { return t > cut.last_source_time_ns; }));
    return;
  }
  const WriterCut& latest = w.end ? *w.end : *w.start;
  if (cut.published > latest.published && cut.last_source_time_ns > latest.last_source_time_ns)
    w.end = cut;
}

std::map<WriterGid, WriterReconciliation> ReceiptLedger::results() const {
  std::map<WriterGid, WriterReconciliation> out;
  for (const auto& [gid, w] : writers_) {
    WriterReconciliation r;
    r.received = w.received;
    r.reports = w.reports;
    if (w.start && w.end) {
      const std::int64_t end_ns = w.end->last_source_time_ns;
      const auto beyond = static_cast<std::uint64_t>(std::count_if(
          w.recent.begin(), w.recent.end(), [&](std::int64_t t) { return t > end_ns; }));
      // Everything received after the end anchor is still among the recent receipts unless
      // the reports fell more than kRecentReceipts samples behind: then no exact figure.
      const bool complete = w.recent.size() < kRecentReceipts || w.recent.front() <= end_ns;
      if (complete) {
        r.reconciled = true;
        r.window_start_ns = w.start->last_source_time_ns;
        r.window_end_ns = end_ns;
        r.expected = w.end->published - w.start->published;
        r.received_in_window = w.after_start - std::min(beyond, w.after_start);
        r.missing = r.expected - std::min(r.expected, r.received_in_window);
        r.duplicates = r.received_in_window - std::min(r.expected, r.received_in_window);
      }
    }
    out.emplace(gid, r);
  }
  return out;
}

std::map<WriterGid, ReceiptLedger::Progress> ReceiptLedger::progress() const {
  std::map<WriterGid, Progress> out;
  for (const auto& [gid, w] : writers_)
    if (w.received > 0) out.emplace(gid, Progress{w.received, w.newest});
  return out;
}

std::uint64_t ReceiptLedger::reports(const WriterGid& writer) const {
  auto it = writers_.find(writer);
  return it == writers_.end() ? 0 : it->second.reports;
}

}  // namespace avs::bag
