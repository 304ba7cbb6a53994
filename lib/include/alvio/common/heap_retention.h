#pragma once
// glibc hands freed heap memory back to the kernel once more than 128 kB sit free at
// the top of the heap, so the image-sized temporaries that OpenCV allocates on every
// frame (pyramids, eigenvalue maps, LSD buffers) are page-faulted in again and zeroed
// on every call. One goodFeaturesToTrack call on a 752x480 frame took 10.5 ms that way
// and 4.5 ms with the memory kept (docs/benchmarks.md, eleventh session).

#include <cstddef>

namespace alvio {

/// Keep up to `trim_bytes` of freed memory in the process, and serve allocations up to
/// glibc's largest mmap threshold (32 MB) from the heap. Process-wide: call it from a
/// program's main(), not from library code. Returns false where the allocator refuses
/// (not glibc). launch/alvio.launch sets the same thresholds through GLIBC_TUNABLES.
bool retainFreedHeapMemory(std::size_t trim_bytes = std::size_t{64} << 20);

}  // namespace alvio
