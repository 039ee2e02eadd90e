#pragma once
// Per-thread scratch buffers for the schemes' block loops.
#include <omp.h>

#include <memory>
#include <vector>

namespace loam {

/// One T per OpenMP thread, each allocated and initialised (first touched) by its own thread, so
/// buffers rewritten every block never share a cache line or page with another thread's.
/// `init(T&)` sizes the buffers. Index the result with omp_get_thread_num().
template <class T, class Init>
std::vector<std::unique_ptr<T>> per_thread_scratch(int threads, Init&& init) {
  std::vector<std::unique_ptr<T>> out(size_t(threads > 0 ? threads : 1));
#pragma omp parallel num_threads(int(out.size()))
  {
    auto s = std::make_unique<T>();
    init(*s);
    out[size_t(omp_get_thread_num())] = std::move(s);
  }
  return out;
}

}  // namespace loam
