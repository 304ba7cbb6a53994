#include "alvio/common/timing.h"

#include <algorithm>
#include <cstdio>
#include <sstream>

namespace alvio {

void FrameTiming::add(const std::string& stage, double ms) {
  for (auto& [name, value] : stages_ms)
    if (name == stage) {
      value += ms;
      return;
    }
  stages_ms.emplace_back(stage, ms);
}

double FrameTiming::total() const {
  double sum = 0;
  for (const auto& s : stages_ms) sum += s.second;
  return sum;
}

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  const double pos = p / 100.0 * (v.size() - 1);
  const std::size_t lo = static_cast<std::size_t>(pos);
  const std::size_t hi = std::min(lo + 1, v.size() - 1);
  return v[lo] + (pos - lo) * (v[hi] - v[lo]);
}

std::vector<std::string> TimingLog::stages() const {
  std::vector<std::string> names;
  for (const auto& f : frames_)
    for (const auto& s : f.stages_ms)
      if (std::find(names.begin(), names.end(), s.first) == names.end()) names.push_back(s.first);
  return names;
}

namespace {
double stageOf(const FrameTiming& f, const std::string& stage) {
  for (const auto& s : f.stages_ms)
    if (s.first == stage) return s.second;
  return 0.0;
}
StageSummary summarise(const std::string& name, const std::vector<double>& values) {
  StageSummary s;
  s.stage = name;
  s.frames = values.size();
  s.median_ms = percentile(values, 50);
  s.p95_ms = percentile(values, 95);
  s.max_ms = values.empty() ? 0 : *std::max_element(values.begin(), values.end());
  double sum = 0;
  for (double v : values) sum += v;
  s.mean_ms = values.empty() ? 0 : sum / values.size();
  return s;
}
}  // namespace

std::vector<StageSummary> TimingLog::summary() const {
  std::vector<StageSummary> out;
  for (const auto& name : stages()) {
    std::vector<double> values;
    for (const auto& f : frames_) values.push_back(stageOf(f, name));
    out.push_back(summarise(name, values));
  }
  std::vector<double> totals;
  for (const auto& f : frames_) totals.push_back(f.total());
  out.push_back(summarise("total", totals));
  return out;
}

std::string TimingLog::toCsv() const {
  const auto names = stages();
  std::ostringstream os;
  os << "t";
  for (const auto& n : names) os << "," << n << "_ms";
  os << ",total_ms\n";
  char buf[64];
  for (const auto& f : frames_) {
    std::snprintf(buf, sizeof(buf), "%.9f", f.t);
    os << buf;
    for (const auto& n : names) {
      std::snprintf(buf, sizeof(buf), ",%.4f", stageOf(f, n));
      os << buf;
    }
    std::snprintf(buf, sizeof(buf), ",%.4f\n", f.total());
    os << buf;
  }
  return os.str();
}

std::string TimingLog::summaryTable() const {
  std::ostringstream os;
  os << "| stage | median ms | p95 ms | max ms | mean ms |\n|---|---:|---:|---:|---:|\n";
  char buf[256];
  for (const auto& s : summary()) {
    std::snprintf(buf, sizeof(buf), "| %s | %.2f | %.2f | %.2f | %.2f |\n", s.stage.c_str(),
                  s.median_ms, s.p95_ms, s.max_ms, s.mean_ms);
    os << buf;
  }
  return os.str();
}

}  // namespace alvio
