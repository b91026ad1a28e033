// sphc runtime: transparent huge pages for the large allocations of a solver.
//
// A solver's large blocks (each property of a particle array, the neighbour search's cell
// tables, the outer vector of the kept lists, the scratch of a re-sort) are std::vectors, and
// every std::vector allocates through the global operator new. The runtime replaces that
// operator (runtime/src/huge_pages.cpp) with allocate(): a block of kHugePageBytes (2 MiB) or
// more is placed at a 2 MiB boundary, its size rounded up to whole 2 MiB pages, and advised
// with madvise(MADV_HUGEPAGE) before anything touches it, so that Linux backs it with
// transparent huge pages where /sys/kernel/mm/transparent_hugepage/enabled is `madvise`
// or `always` (one TLB entry per 2 MiB instead of 512). Smaller blocks are malloc's as
// before, and every block is returned with free(). Nothing but placement changes: the values
// and the order of every computation are the same, so the outputs are bitwise equal.
//
// The switch: `--huge-pages=on|off` of a solver, or the environment variable
// SPHC_HUGE_PAGES=on|off (the option wins; read when the first large block is allocated).
// Off by default (docs/performance.md, "Transparent huge pages for the large allocations":
// measured, no gain beyond the spread). Linux only: elsewhere, and where madvise refuses
// (a kernel without THP, `never`), the blocks are allocated as without it.
#pragma once

#include <cstddef>

namespace sphc {

// The size of a transparent huge page on x86-64 and the threshold of allocate().
constexpr std::size_t kHugePageBytes = std::size_t(2) << 20;

// Whether allocate() places large blocks on huge pages (set_huge_pages, else SPHC_HUGE_PAGES
// = on / off, else off).
bool huge_pages_enabled();
void set_huge_pages(bool on);

// "on" / "off" (also 1 / 0, true / false, yes / no): the switch's value; -1 if not one of them.
int parse_huge_pages(const char* text);

// madvise(MADV_HUGEPAGE) on the whole 2 MiB pages inside [p, p + bytes). False where there is
// no such page, where madvise is refused (errno kept), or off Linux.
bool advise_huge_pages(void* p, std::size_t bytes);

// `bytes` from malloc, or, with huge pages on and bytes >= kHugePageBytes, from
// aligned_alloc(kHugePageBytes, bytes rounded up to kHugePageBytes) advised with
// advise_huge_pages (a refused madvise leaves the block as it is). nullptr if out of memory.
// Release with std::free either way.
void* allocate(std::size_t bytes);

// Counters of allocate() since the start (for tests and --timing): large blocks asked for
// with huge pages on, and those madvise accepted.
struct HugePageCounts {
  std::size_t large_blocks = 0;
  std::size_t advised_blocks = 0;
};
HugePageCounts huge_page_counts();

namespace detail {
// The madvise allocate() calls (tests replace it to make it refuse); nullptr: the system's.
using MadviseFn = int (*)(void*, std::size_t, int);
void set_madvise_for_tests(MadviseFn fn);
}  // namespace detail

}  // namespace sphc
