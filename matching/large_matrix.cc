#include "matching/large_matrix.h"

#include <sys/mman.h>

#include <cstdlib>
#include <new>

namespace openable {
namespace {

// cv::MatAllocator is OpenCV's hook for where a Mat's memory comes from; this one differs from
// the default only in alignment and the madvise call.
class HugePageAllocator final : public cv::MatAllocator {
 public:
  cv::UMatData* allocate(int dims, const int* sizes, int type, void* data0, size_t* step,
                         cv::AccessFlag /*flags*/, cv::UMatUsageFlags /*usage*/) const override {
    size_t total = CV_ELEM_SIZE(type);
    for (int i = dims - 1; i >= 0; --i) {
      if (step != nullptr) {
        if (data0 != nullptr && step[i] != cv::Mat::AUTO_STEP) {
          total = step[i] * static_cast<size_t>(sizes[i]);
          continue;
        }
        step[i] = total;
      }
      total *= static_cast<size_t>(sizes[i]);
    }
    auto* u = new cv::UMatData(this);
    u->size = total;
    if (data0 != nullptr) {
      u->data = u->origdata = static_cast<uchar*>(data0);
      u->flags |= cv::UMatData::USER_ALLOCATED;
      return u;
    }
    constexpr size_t kHuge = size_t{2} << 20;
    void* p = nullptr;
    const size_t rounded = (total + kHuge - 1) / kHuge * kHuge;
    if (posix_memalign(&p, kHuge, rounded) != 0) {
      delete u;
      throw std::bad_alloc();
    }
#ifdef MADV_HUGEPAGE
    madvise(p, rounded, MADV_HUGEPAGE);  // advice only: ignored where THP is off
#endif
    u->data = u->origdata = static_cast<uchar*>(p);
    return u;
  }

  bool allocate(cv::UMatData* u, cv::AccessFlag /*flags*/,
                cv::UMatUsageFlags /*usage*/) const override {
    return u != nullptr;
  }

  void deallocate(cv::UMatData* u) const override {
    if (u == nullptr) return;
    if ((u->flags & cv::UMatData::USER_ALLOCATED) == 0) std::free(u->origdata);
    delete u;
  }
};

HugePageAllocator& Allocator() {
  static HugePageAllocator* allocator = new HugePageAllocator();  // outlives every Mat
  return *allocator;
}

}  // namespace

cv::Mat1f LargeMatrix(int rows, int cols) {
  cv::Mat1f m;
  if (static_cast<double>(rows) * cols * sizeof(float) >= 8.0 * (1 << 20))
    m.allocator = &Allocator();
  m.create(rows, cols);
  return m;
}

}  // namespace openable
