// sphc runtime: transparent huge pages for the large allocations (sphc/huge_pages.h), and the
// global operator new / delete that route every allocation of a solver through allocate().
#include "sphc/huge_pages.h"

#include <atomic>
#include <cerrno>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <initializer_list>
#include <new>

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace sphc {

namespace {

// -1: not decided yet (SPHC_HUGE_PAGES is read at the first large block), 0 off, 1 on.
std::atomic<int> g_state{-1};
std::atomic<detail::MadviseFn> g_madvise{nullptr};
std::atomic<std::size_t> g_large{0}, g_advised{0};

}  // namespace

int parse_huge_pages(const char* text) {
  if (!text) return -1;
  for (const char* on : {"on", "1", "true", "yes"})
    if (std::strcmp(text, on) == 0) return 1;
  for (const char* off : {"off", "0", "false", "no"})
    if (std::strcmp(text, off) == 0) return 0;
  return -1;
}

bool huge_pages_enabled() {
  int s = g_state.load(std::memory_order_relaxed);
  if (s < 0) {
    const int env = parse_huge_pages(std::getenv("SPHC_HUGE_PAGES"));
    s = env < 0 ? 0 : env;  // unset or not understood: the default, off
    int expected = -1;
    if (!g_state.compare_exchange_strong(expected, s)) s = expected;
  }
  return s == 1;
}

void set_huge_pages(bool on) { g_state.store(on ? 1 : 0); }

bool advise_huge_pages(void* p, std::size_t bytes) {
#if defined(__linux__) && defined(MADV_HUGEPAGE)
  const std::uintptr_t a = reinterpret_cast<std::uintptr_t>(p);
  const std::uintptr_t lo = (a + kHugePageBytes - 1) & ~(std::uintptr_t(kHugePageBytes) - 1);
  const std::uintptr_t hi = (a + bytes) & ~(std::uintptr_t(kHugePageBytes) - 1);
  if (!p || hi <= lo) return false;
  detail::MadviseFn fn = g_madvise.load(std::memory_order_relaxed);
  void* start = reinterpret_cast<void*>(lo);
  const int rc = fn ? fn(start, hi - lo, MADV_HUGEPAGE) : ::madvise(start, hi - lo, MADV_HUGEPAGE);
  return rc == 0;
#else
  (void)p;
  (void)bytes;
  return false;
#endif
}

void* allocate(std::size_t bytes) {
  if (bytes < kHugePageBytes || !huge_pages_enabled()) return std::malloc(bytes ? bytes : 1);
  const std::size_t rounded = (bytes + kHugePageBytes - 1) & ~(kHugePageBytes - 1);
  if (rounded < bytes) return nullptr;  // overflow
  void* p = std::aligned_alloc(kHugePageBytes, rounded);
  if (!p) return nullptr;
  g_large.fetch_add(1, std::memory_order_relaxed);
  const int saved = errno;
  if (advise_huge_pages(p, rounded)) g_advised.fetch_add(1, std::memory_order_relaxed);
  errno = saved;  // a refused madvise is no error of the allocation
  return p;
}

HugePageCounts huge_page_counts() {
  HugePageCounts c;
  c.large_blocks = g_large.load();
  c.advised_blocks = g_advised.load();
  return c;
}

namespace detail {
void set_madvise_for_tests(MadviseFn fn) { g_madvise.store(fn); }
}  // namespace detail

}  // namespace sphc

// The replaceable global allocation functions (C++17 [new.delete]): every allocation of a
// program linked with the runtime (a solver, the runtime's tests) goes through
// sphc::allocate, which is malloc below 2 MiB or with huge pages off, so the program behaves
// as with the standard library's own (which also uses malloc and free). The over-aligned forms
// stay the library's.
void* operator new(std::size_t bytes) {
  for (;;) {
    if (void* p = sphc::allocate(bytes)) return p;
    std::new_handler h = std::get_new_handler();
    if (!h) throw std::bad_alloc();
    h();
  }
}

void* operator new[](std::size_t bytes) { return ::operator new(bytes); }

void* operator new(std::size_t bytes, const std::nothrow_t&) noexcept {
  try {
    return ::operator new(bytes);
  } catch (...) {
    return nullptr;
  }
}

void* operator new[](std::size_t bytes, const std::nothrow_t&) noexcept {
  return ::operator new(bytes, std::nothrow);
}

void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
void operator delete(void* p, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete[](void* p, const std::nothrow_t&) noexcept { std::free(p); }
