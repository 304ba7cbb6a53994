#include "alvio/common/heap_retention.h"

#include <algorithm>
#include <climits>

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace alvio {

bool retainFreedHeapMemory(std::size_t trim_bytes) {
#if defined(__GLIBC__)
  // A fixed mmap threshold also stops glibc from lowering the trim threshold again.
  constexpr int kLargestMmapThreshold = 32 << 20;  // glibc's DEFAULT_MMAP_THRESHOLD_MAX
  const bool mmap_ok = mallopt(M_MMAP_THRESHOLD, kLargestMmapThreshold) == 1;
  const bool trim_ok =
      mallopt(M_TRIM_THRESHOLD, static_cast<int>(std::min<std::size_t>(trim_bytes, INT_MAX))) == 1;
  return mmap_ok && trim_ok;
#else
  (void)trim_bytes;
  return false;
#endif
}

}  // namespace alvio
