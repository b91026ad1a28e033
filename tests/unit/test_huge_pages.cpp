// sphc/huge_pages.h: the 2 MiB threshold, the alignment and rounding of large blocks, the
// switch, a refused madvise, and the global operator new routed through allocate().
#include "sphc/huge_pages.h"

#include <gtest/gtest.h>

#include <malloc.h>

#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <vector>

namespace {

using sphc::kHugePageBytes;

bool aligned_2m(const void* p) {
  return reinterpret_cast<std::uintptr_t>(p) % kHugePageBytes == 0;
}

struct Advice {
  std::uintptr_t start = 0;
  std::size_t bytes = 0;
  int calls = 0;
};
Advice g_advice;

int refuse(void* start, std::size_t bytes, int) {
  g_advice.start = reinterpret_cast<std::uintptr_t>(start);
  g_advice.bytes = bytes;
  ++g_advice.calls;
  errno = EINVAL;
  return -1;
}

int accept(void* start, std::size_t bytes, int) {
  g_advice.start = reinterpret_cast<std::uintptr_t>(start);
  g_advice.bytes = bytes;
  ++g_advice.calls;
  return 0;
}

// Restores the switch and the system's madvise after each test.
class HugePages : public ::testing::Test {
 protected:
  void SetUp() override { was_on_ = sphc::huge_pages_enabled(); }
  void TearDown() override {
    sphc::set_huge_pages(was_on_);
    sphc::detail::set_madvise_for_tests(nullptr);
  }
  // The switch, the madvise allocate() calls, no advice seen yet, the counts now.
  void start(bool on, sphc::detail::MadviseFn fn) {
    sphc::set_huge_pages(on);
    sphc::detail::set_madvise_for_tests(fn);
    g_advice = {};
    before_ = sphc::huge_page_counts();
  }
  bool was_on_ = false;
  sphc::HugePageCounts before_;
};

TEST_F(HugePages, ParsesTheSwitch) {
  EXPECT_EQ(sphc::parse_huge_pages("on"), 1);
  EXPECT_EQ(sphc::parse_huge_pages("1"), 1);
  EXPECT_EQ(sphc::parse_huge_pages("off"), 0);
  EXPECT_EQ(sphc::parse_huge_pages("no"), 0);
  EXPECT_EQ(sphc::parse_huge_pages("huge"), -1);
  EXPECT_EQ(sphc::parse_huge_pages(""), -1);
  EXPECT_EQ(sphc::parse_huge_pages(nullptr), -1);
}

TEST_F(HugePages, LargeBlocksAreAlignedRoundedAndAdvised) {
  start(true, accept);
  const std::size_t bytes = 3 * kHugePageBytes + 12345;
  void* p = sphc::allocate(bytes);
  ASSERT_NE(p, nullptr);
  EXPECT_TRUE(aligned_2m(p));
  EXPECT_GE(malloc_usable_size(p), 4 * kHugePageBytes);  // rounded up to whole huge pages
  // The advice covers the whole rounded block, nothing outside it.
  EXPECT_EQ(g_advice.calls, 1);
  EXPECT_EQ(g_advice.start, reinterpret_cast<std::uintptr_t>(p));
  EXPECT_EQ(g_advice.bytes, 4 * kHugePageBytes);
  const sphc::HugePageCounts after = sphc::huge_page_counts();
  EXPECT_EQ(after.large_blocks, before_.large_blocks + 1);
  EXPECT_EQ(after.advised_blocks, before_.advised_blocks + 1);
  std::memset(p, 7, bytes);
  std::free(p);
}

TEST_F(HugePages, BelowTheThresholdIsMallocs) {
  start(true, accept);
  void* p = sphc::allocate(kHugePageBytes - 1);
  ASSERT_NE(p, nullptr);
  EXPECT_EQ(g_advice.calls, 0);
  EXPECT_EQ(sphc::huge_page_counts().large_blocks, before_.large_blocks);
  std::free(p);
  void* q = sphc::allocate(kHugePageBytes);  // the threshold itself is large
  ASSERT_NE(q, nullptr);
  EXPECT_TRUE(aligned_2m(q));
  EXPECT_EQ(g_advice.calls, 1);
  EXPECT_EQ(sphc::huge_page_counts().large_blocks, before_.large_blocks + 1);
  std::free(q);
}

TEST_F(HugePages, OffMeansNoAdviceAndNoRounding) {
  start(false, accept);
  EXPECT_FALSE(sphc::huge_pages_enabled());
  const std::size_t bytes = 3 * kHugePageBytes + 12345;
  void* p = sphc::allocate(bytes);
  ASSERT_NE(p, nullptr);
  EXPECT_EQ(g_advice.calls, 0);
  EXPECT_LT(malloc_usable_size(p), 4 * kHugePageBytes);  // malloc's size, not whole pages
  EXPECT_EQ(sphc::huge_page_counts().large_blocks, before_.large_blocks);
  std::free(p);
}

TEST_F(HugePages, RefusedAdviceLeavesAUsableBlock) {
  start(true, refuse);
  errno = 0;
  const std::size_t bytes = 5 * kHugePageBytes;
  auto* p = static_cast<unsigned char*>(sphc::allocate(bytes));
  ASSERT_NE(p, nullptr);
  EXPECT_EQ(errno, 0);  // the refusal is not reported as an error of the allocation
  EXPECT_EQ(g_advice.calls, 1);
  const sphc::HugePageCounts after = sphc::huge_page_counts();
  EXPECT_EQ(after.large_blocks, before_.large_blocks + 1);
  EXPECT_EQ(after.advised_blocks, before_.advised_blocks);
  std::memset(p, 3, bytes);
  EXPECT_EQ(p[bytes - 1], 3);
  std::free(p);
}

TEST_F(HugePages, AdvisesOnlyWholeHugePagesInsideTheRange) {
  sphc::detail::set_madvise_for_tests(accept);
  g_advice = {};
  void* block = std::aligned_alloc(kHugePageBytes, 4 * kHugePageBytes);
  ASSERT_NE(block, nullptr);
  auto base = reinterpret_cast<std::uintptr_t>(block);
  // From 1 byte past the first huge page to 1 byte short of the fourth's end: pages 2 and 3.
  EXPECT_TRUE(sphc::advise_huge_pages(reinterpret_cast<void*>(base + 1),
                                      4 * kHugePageBytes - 2));
  EXPECT_EQ(g_advice.start, base + kHugePageBytes);
  EXPECT_EQ(g_advice.bytes, 2 * kHugePageBytes);
  // No whole huge page inside: no call.
  g_advice = {};
  EXPECT_FALSE(sphc::advise_huge_pages(reinterpret_cast<void*>(base + 1), kHugePageBytes));
  EXPECT_EQ(g_advice.calls, 0);
  std::free(block);
}

#if defined(__linux__)
// The system's madvise accepts the advice where the kernel has transparent huge pages.
TEST_F(HugePages, TheKernelAcceptsTheAdvice) {
  if (std::FILE* f = std::fopen("/sys/kernel/mm/transparent_hugepage/enabled", "r"))
    std::fclose(f);
  else
    GTEST_SKIP() << "no transparent huge pages in this kernel";
  start(true, nullptr);  // the system's madvise
  void* p = sphc::allocate(2 * kHugePageBytes);
  ASSERT_NE(p, nullptr);
  EXPECT_EQ(sphc::huge_page_counts().advised_blocks, before_.advised_blocks + 1);
  std::free(p);
}
#endif

// std::vector allocates through the replaced operator new: a large vector gets the 2 MiB
// placement with the switch on and malloc's without.
TEST_F(HugePages, VectorsGoThroughTheReplacedOperatorNew) {
  sphc::detail::set_madvise_for_tests(accept);
  sphc::set_huge_pages(true);
  const std::size_t large_before = sphc::huge_page_counts().large_blocks;
  {
    std::vector<double> v(kHugePageBytes / sizeof(double) + 1, 1.0);
    EXPECT_TRUE(aligned_2m(v.data()));
    EXPECT_EQ(sphc::huge_page_counts().large_blocks, large_before + 1);
  }
  sphc::set_huge_pages(false);
  {
    std::vector<double> v(kHugePageBytes / sizeof(double) + 1, 1.0);
    EXPECT_EQ(sphc::huge_page_counts().large_blocks, large_before + 1);
  }
}

}  // namespace
