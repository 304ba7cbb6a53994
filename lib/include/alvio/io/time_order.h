#pragma once
// Checks that records read from a file are strictly increasing in time. Unsorted
// or duplicate stamps are never accepted silently: they are an error, or, when
// the caller allows it, sorted/dropped with a warning that gives the counts.

#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

#include "alvio/common/error.h"
#include "alvio/common/logging.h"

namespace alvio {

enum class TimeOrderPolicy {
  kStrict,       ///< throw alvio::Error at the first unsorted or duplicate stamp
  kSortAndDedup  ///< sort, keep the first of duplicates, log a warning with counts
};

struct TimeOrderReport {
  int unsorted = 0;
  int duplicates = 0;
};

/// `stamp(r)` gives a record's time as int64 ns; `lines[i]` is record i's line number.
template <typename Record, typename Alloc, typename StampFn>
TimeOrderReport enforceTimeOrder(std::vector<Record, Alloc>* records, const std::vector<int>& lines,
                                 const std::string& path, TimeOrderPolicy policy, StampFn stamp) {
  TimeOrderReport report;
  for (std::size_t i = 1; i < records->size(); ++i) {
    const int64_t prev = stamp((*records)[i - 1]);
    const int64_t cur = stamp((*records)[i]);
    if (cur > prev) continue;
    if (policy == TimeOrderPolicy::kStrict) {
      throw Error(path + ":" + std::to_string(lines[i]) + ": timestamp " + std::to_string(cur) +
                  (cur == prev ? " duplicates" : " is earlier than") + " the previous record's (" +
                  std::to_string(prev) + ", line " + std::to_string(lines[i - 1]) + ")");
    }
    ++(cur == prev ? report.duplicates : report.unsorted);
  }
  if (report.unsorted + report.duplicates == 0) return report;
  std::stable_sort(records->begin(), records->end(),
                   [&](const Record& a, const Record& b) { return stamp(a) < stamp(b); });
  const auto before = records->size();
  records->erase(
      std::unique(records->begin(), records->end(),
                  [&](const Record& a, const Record& b) { return stamp(a) == stamp(b); }),
      records->end());
  logWarn(path, ": ", report.unsorted, " out-of-order and ", report.duplicates,
          " duplicate timestamps; sorted and dropped ", before - records->size(), " duplicates");
  return report;
}

}  // namespace alvio
