#pragma once
// f(i) for i in [0, n) on `threads` threads, statically interleaved so that every index
// always runs the same computation (deterministic output whatever the thread count).

#include <algorithm>
#include <thread>
#include <vector>

namespace alvio::sim {

template <typename F>
void parallelFor(int n, int threads, F&& f) {
  threads = std::max(1, std::min(threads, n));
  std::vector<std::thread> pool;
  for (int k = 1; k < threads; ++k)
    pool.emplace_back([&, k] {
      for (int i = k; i < n; i += threads) f(i);
    });
  for (int i = 0; i < n; i += threads) f(i);
  for (auto& t : pool) t.join();
}

}  // namespace alvio::sim
