// Heap policy for one large call (glibc only; a no-op elsewhere).
//
// glibc serves a block above its mmap threshold from a fresh mmap and unmaps it on
// free.  It raises that threshold by itself, but only up to 32 MiB, so on a mesh of a
// million faces every (#E, 3) work array is fresh memory and each of its pages faults
// on first touch: 400k minor faults per drop-in call on 1.31M faces.  While a scope is
// open the threshold is raised so that a call's work arrays come from the heap and are
// reused from one stage to the next; when the last open scope closes, the threshold
// returns to glibc's own 32 MiB ceiling and malloc_trim(0) hands the freed heap back to
// the system, so nothing is kept between calls.  Scopes nest and may be opened from
// several threads (a depth count under a mutex).
#include <algorithm>
#include <climits>
#include <mutex>
#if defined(__GLIBC__)
#include <malloc.h>
#endif

#include "core.hpp"

namespace hhj {

namespace {
std::mutex heap_mutex;
int heap_depth = 0;
bool heap_raised = false;
constexpr int GLIBC_MMAP_THRESHOLD_MAX = 32 << 20;   // DEFAULT_MMAP_THRESHOLD_MAX (64-bit)
}  // namespace

bool heap_scope_enter(std::size_t mmap_threshold) {
    std::lock_guard<std::mutex> lock(heap_mutex);
    ++heap_depth;
#if defined(__GLIBC__)
    if (heap_depth == 1) {
        const int t = (int)std::min<std::size_t>(std::max<std::size_t>(mmap_threshold, GLIBC_MMAP_THRESHOLD_MAX),
                                                 (std::size_t)1 << 30);
        heap_raised = mallopt(M_MMAP_THRESHOLD, t) == 1;
        if (heap_raised) mallopt(M_TRIM_THRESHOLD, INT_MAX);     // no trimming inside the call
    }
#endif
    return heap_raised;
}

bool heap_scope_exit() {
    std::lock_guard<std::mutex> lock(heap_mutex);
    if (heap_depth == 0) return false;
    if (--heap_depth > 0 || !heap_raised) return false;
    heap_raised = false;
#if defined(__GLIBC__)
    mallopt(M_MMAP_THRESHOLD, GLIBC_MMAP_THRESHOLD_MAX);
    mallopt(M_TRIM_THRESHOLD, 2 * GLIBC_MMAP_THRESHOLD_MAX);   // glibc's rule: 2x the threshold
    malloc_trim(0);
    return true;
#else
    return false;
#endif
}

int heap_scope_depth() {
    std::lock_guard<std::mutex> lock(heap_mutex);
    return heap_depth;
}

}  // namespace hhj
