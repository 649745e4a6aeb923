// The one place OpenABLE calls a BLAS: the float matrix products of the L2 distance matrices
// (HOG, SIFT, sub-panoramas), on Debian's OpenBLAS (dlopen of libopenblas.so.0 on first use),
// which picks its kernels for the CPU at run time where Eigen would be built for the baseline
// instruction set. An OpenBLAS older than the CPU (Debian 12's 0.3.21 on Intel Xeon model 207)
// falls back to its slow SSE3 ("Prescott") kernels; OpenABLE then has it choose again with
// OPENBLAS_CORETYPE naming the CPU's (SkylakeX, Haswell) unless the user set that variable. The
// kernels are the whole process's (numpy's too). docs/benchmarks.md, "Matching kernels".
#pragma once

#include <string>

namespace openable {

// C = A B^T for row-major float matrices, on the calling thread: A is `rows` x `width` (rows
// `lda` floats apart), B is `cols` x `width` (rows `ldb` apart), C is `rows` x `cols` (rows
// `ldc` apart). Callers spread products over threads themselves (one product per tile), so a
// cell's value depends only on the shape of the product it is computed in, never on the
// thread count. Safe to call from several threads at once.
//
// OpenBLAS has one process-wide thread count: it is 1 while products of OpenABLE run, and the
// host program's own setting is put back when the last one ends. A single-threaded or OpenMP
// build of OpenBLAS chosen by the system (update-alternatives) runs one product at a time.
//
// Throws InputError when libopenblas.so.0 cannot be loaded (package libopenblas0).
void MultiplyTransposed(const float* a, int rows, int lda, const float* b, int cols, int ldb,
                        int width, float* c, int ldc);

// While one lives, OpenBLAS runs this CPU's kernels (loaded as above) and its process-wide
// thread count is 1 (as while MultiplyTransposed runs; the host's count is put back when the
// last ends): for a library that calls BLAS itself from threads of its own (FAISS's k-means on
// OpenMP, whose products go through Debian's libblas.so.3, the same OpenBLAS), where
// OpenBLAS's threads would compete with its own for the cores. Nothing when OpenBLAS cannot be
// loaded: that library then uses the BLAS the system chose.
class BlasOnOneThread {
 public:
  BlasOnOneThread();
  ~BlasOnOneThread();
  BlasOnOneThread(const BlasOnOneThread&) = delete;
  BlasOnOneThread& operator=(const BlasOnOneThread&) = delete;

 private:
  bool active_ = false;
};

// OpenBLAS's own description ("OpenBLAS 0.3.21 DYNAMIC_ARCH ... SkylakeX"), its kernels and
// threading, and whether OpenABLE chose the kernels: for benchmarks and bug reports.
std::string BlasDescription();

}  // namespace openable
