// The one place OpenABLE calls a BLAS: the float matrix products of the L2 distance matrices
// (HOG, SIFT, the descriptors of the sub-panoramas), on Debian's OpenBLAS, which picks its
// kernels for the CPU at run time (AVX-512 on the machines of docs/benchmarks.md), where a
// product compiled with the project (Eigen's) is built for the baseline instruction set.
//
// OpenBLAS is found on first use (dlopen of libopenblas.so.0; OpenCV's LAPACK has usually
// loaded it already). An OpenBLAS older than the CPU (Debian 12's 0.3.21 on Intel Xeon model
// 207) does not recognise it and runs its SSE3 kernels ("Prescott"), four times slower than
// its AVX-512 ones there. OpenABLE then runs OpenBLAS's start-up choice again with OpenBLAS's
// own setting OPENBLAS_CORETYPE naming the kernels of the CPU's instruction sets (SkylakeX
// for AVX-512, Haswell for AVX2 and FMA), unless the user has set that variable. The kernels
// are those of the whole process (one OpenBLAS: numpy in the same Python process too).
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
