#pragma once
#include <sys/mman.h>

#include <algorithm>
#include <cstddef>
#include <cstdlib>
#include <new>

namespace diefill {

// An allocator that puts arrays of half a MiB and more on transparent huge pages (madvise mode, which
// Debian's kernels default to). Every DEM stage streams through every grain and pair each step: in
// 4 KiB pages a 50k pack spans thousands of pages, and in a virtual machine each TLB miss walks the
// guest's and the host's page tables; runs whose memory the host had backed poorly ran all
// stages 1.5 times slower, in half the processes (docs/PERFORMANCE.md, "How the kernel is built, and why"). A wall's
// triangles are read at random, a page or more per grain near the wall (geometry/wall_field.hpp).
template <class T>
struct HugePageAllocator {
  using value_type = T;
  static constexpr std::size_t huge_page = std::size_t(2) << 20;
  static constexpr std::size_t smallest_huge = huge_page / 4;  // a 50k pack's arrays are 0.2-1.2 MiB
  static constexpr std::size_t alignment = std::max(alignof(T), alignof(std::max_align_t));
  HugePageAllocator() = default;
  template <class U>
  HugePageAllocator(const HugePageAllocator<U>&) noexcept {}
  T* allocate(std::size_t n) {
    const std::size_t bytes = n * sizeof(T);
    const std::size_t page = bytes < smallest_huge ? alignment : huge_page;
    const std::size_t rounded = std::max<std::size_t>((bytes + page - 1) / page * page, page);
    void* p = std::aligned_alloc(page, rounded);
    if (!p) throw std::bad_alloc();
    if (page == huge_page) madvise(p, rounded, MADV_HUGEPAGE);  // a hint: without huge pages the array works as before
    return static_cast<T*>(p);
  }
  void deallocate(T* p, std::size_t) noexcept { std::free(p); }
  template <class U>
  bool operator==(const HugePageAllocator<U>&) const noexcept { return true; }
};

}  // namespace diefill
