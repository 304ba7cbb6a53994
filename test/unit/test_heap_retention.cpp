// retainFreedHeapMemory: a frame-sized temporary is served from the heap, and freeing it
// keeps the memory in the process instead of handing it back to the kernel.
#include <gtest/gtest.h>

#include <cstdlib>
#include <cstring>

#include "alvio/common/heap_retention.h"

#if defined(__GLIBC__)
#include <malloc.h>
#endif

// AddressSanitizer replaces glibc's allocator, so mallopt has nothing to tune there.
#if defined(__SANITIZE_ADDRESS__)
#define ALVIO_GLIBC_ALLOCATOR 0
#elif defined(__GLIBC__)
#define ALVIO_GLIBC_ALLOCATOR 1
#else
#define ALVIO_GLIBC_ALLOCATOR 0
#endif

TEST(HeapRetention, FrameSizedTemporariesComeFromTheHeapAndStayThere) {
#if !ALVIO_GLIBC_ALLOCATOR
  GTEST_SKIP() << "glibc's own allocator only (not under AddressSanitizer)";
#else
  ASSERT_TRUE(alvio::retainFreedHeapMemory());
  constexpr std::size_t kBytes = std::size_t{8} << 20;  // several 752x480 float images
  const std::size_t mmapped_before = mallinfo2().hblkhd;
  char* block = static_cast<char*>(std::malloc(kBytes));
  ASSERT_NE(block, nullptr);
  std::memset(block, 1, kBytes);
  asm volatile("" : : "r"(block) : "memory");  // keep the allocation
  EXPECT_LT(mallinfo2().hblkhd, mmapped_before + kBytes)
      << "served by mmap: such a block is faulted in again on every frame";
  std::free(block);
  EXPECT_GE(mallinfo2().keepcost, kBytes) << "trimmed: handed back to the kernel on free";
#endif
}
