#pragma once
#include <Eigen/Core>
#include <Eigen/Geometry>

#include <sys/mman.h>

#include <cstdlib>
#include <new>
#include <vector>

namespace dem {
using Vec3 = Eigen::Vector3d;
using Quat = Eigen::Quaterniond;

// An allocator that puts arrays of half a MiB and more on transparent huge pages (madvise mode, which
// Debian's kernels default to). Every stage streams through every grain and pair each step: in 4
// KiB pages a 50k pack spans thousands of pages, and in a virtual machine each TLB miss walks the
// guest's and the host's page tables; runs whose memory the host had backed poorly ran all
// stages 1.5 times slower, in half the processes (README, "Speed against LIGGGHTS").
template <class T>
struct HugePageAllocator {
  using value_type = T;
  static constexpr std::size_t huge_page = std::size_t(2) << 20;
  static constexpr std::size_t smallest_huge = huge_page / 4;  // a 50k pack's arrays are 0.2-1.2 MiB
  HugePageAllocator() = default;
  template <class U>
  HugePageAllocator(const HugePageAllocator<U>&) noexcept {}
  T* allocate(std::size_t n) {
    const std::size_t bytes = n * sizeof(T);
    if (bytes < smallest_huge) {
      if (void* p = std::malloc(bytes ? bytes : 1)) return static_cast<T*>(p);
      throw std::bad_alloc();
    }
    const std::size_t rounded = (bytes + huge_page - 1) / huge_page * huge_page;
    void* p = std::aligned_alloc(huge_page, rounded);
    if (!p) throw std::bad_alloc();
    madvise(p, rounded, MADV_HUGEPAGE);  // a hint: without huge pages the array works as before
    return static_cast<T*>(p);
  }
  void deallocate(T* p, std::size_t) noexcept { std::free(p); }
  template <class U>
  bool operator==(const HugePageAllocator<U>&) const noexcept { return true; }
};

// The State's arrays.
template <class T>
using Array = std::vector<T, HugePageAllocator<T>>;

}  // namespace dem
