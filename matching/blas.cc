#include "matching/blas.h"

#include <cblas.h>  // OpenBLAS's (matching/CMakeLists.txt): the types of the calls looked up
#include <dlfcn.h>

#include <cstdlib>
#include <mutex>
#include <set>

#include "OpenABLE/base/error.h"

namespace openable {
namespace {

constexpr const char* kLibrary = "libopenblas.so.0";

// The calls of OpenBLAS used, looked up in the loaded library.
struct OpenBlas {
  void* handle = nullptr;
  decltype(&cblas_sgemm) sgemm = nullptr;
  decltype(&openblas_set_num_threads) set_num_threads = nullptr;
  decltype(&openblas_get_num_threads) get_num_threads = nullptr;
  decltype(&openblas_get_parallel) get_parallel = nullptr;
  decltype(&openblas_get_config) get_config = nullptr;
  decltype(&openblas_get_corename) get_corename = nullptr;
  std::string chosen;    // the OPENBLAS_CORETYPE OpenABLE set, if it did
  bool overlap = false;  // calls from several threads may run at once (pthreads build)
};

template <typename T>
void Look(void* handle, const char* name, T& into) {
  into = reinterpret_cast<T>(dlsym(handle, name));
  if (!into)
    throw InputError(std::string(kLibrary) + " has no " + name +
                     "; expected OpenBLAS (package libopenblas0)");
}

void Open(OpenBlas& b) {
  b.handle = dlopen(kLibrary, RTLD_NOW | RTLD_LOCAL);
  if (!b.handle) {
    const char* why = dlerror();
    throw InputError(std::string("cannot load OpenBLAS for the float distance matrices (") +
                     (why ? why : kLibrary) +
                     "); expected package libopenblas0 "
                     "(examples/setup.sh installs it)");
  }
  Look(b.handle, "cblas_sgemm", b.sgemm);
  Look(b.handle, "openblas_set_num_threads", b.set_num_threads);
  Look(b.handle, "openblas_get_num_threads", b.get_num_threads);
  Look(b.handle, "openblas_get_parallel", b.get_parallel);
  Look(b.handle, "openblas_get_config", b.get_config);
  Look(b.handle, "openblas_get_corename", b.get_corename);
}

// The kernels of OpenBLAS for the instruction sets of this CPU, when OpenBLAS itself chose
// kernels without AVX2 on a CPU that has it (a CPU newer than the library): SkylakeX with the
// AVX-512 subsets those kernels use, Haswell with AVX2 and FMA; empty otherwise (OpenBLAS's
// choice stands, whatever it is on a CPU it knows).
std::string BetterCore(const std::string& loaded) {
  static const std::set<std::string> with_avx2 = {
      "Haswell", "Zen", "SkylakeX", "Cooperlake", "SapphireRapids", "Excavator"};
  if (with_avx2.count(loaded)) return "";
  __builtin_cpu_init();
  if (__builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512bw") &&
      __builtin_cpu_supports("avx512dq") && __builtin_cpu_supports("avx512vl") &&
      __builtin_cpu_supports("avx512cd"))
    return "SkylakeX";
  if (__builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma")) return "Haswell";
  return "";
}

OpenBlas Load() {
  OpenBlas b;
  Open(b);  // usually loaded already: OpenCV's LAPACK is OpenBLAS's when it is installed
  // OpenBLAS (DYNAMIC_ARCH) chose its kernels when it started, from OPENBLAS_CORETYPE or the
  // CPU; on a CPU it does not know, the oldest ones. Its own start-up routine is run again
  // with OPENBLAS_CORETYPE naming the kernels of this CPU's instruction sets (the variable is
  // then removed, so that the environment is as it was). The library is one for the whole
  // process: the host's own BLAS calls (numpy's, in Python) get the faster kernels too.
  // A user who sets OPENBLAS_CORETYPE keeps the kernels named.
  if (!std::getenv("OPENBLAS_CORETYPE")) {
    const std::string core = BetterCore(b.get_corename());
    auto quit = reinterpret_cast<void (*)()>(dlsym(b.handle, "gotoblas_dynamic_quit"));
    auto init = reinterpret_cast<void (*)()>(dlsym(b.handle, "gotoblas_dynamic_init"));
    if (!core.empty() && quit && init) {
      setenv("OPENBLAS_CORETYPE", core.c_str(), 1);
      quit();
      init();
      unsetenv("OPENBLAS_CORETYPE");
      if (core == b.get_corename()) b.chosen = core;
    }
  }
  // A single-threaded OpenBLAS (openblas_get_parallel() == 0) is built without locks and is
  // not safe to call from two threads at once; an OpenMP one may not be either. Those run one
  // product at a time; the pthreads build (Debian's default) runs them side by side.
  b.overlap = b.get_parallel() == 1;
  return b;
}

const OpenBlas& Library() {
  static const OpenBlas library = Load();
  return library;
}

// The process-wide thread count of OpenBLAS while OpenABLE's products run: the first call sets
// it to 1 (keeping the host's), the last puts the host's back.
struct ThreadSetting {
  std::mutex mutex;
  int running = 0;
  int host_threads = 0;
};

ThreadSetting& Setting() {
  static ThreadSetting setting;
  return setting;
}

std::mutex& OneAtATime() {
  static std::mutex mutex;
  return mutex;
}

}  // namespace

BlasOnOneThread::BlasOnOneThread() {
  const OpenBlas* blas = nullptr;
  try {
    blas = &Library();
  } catch (const InputError&) {
    return;  // no OpenBLAS: nothing to set
  }
  ThreadSetting& s = Setting();
  std::lock_guard<std::mutex> lock(s.mutex);
  if (s.running++ == 0) {
    s.host_threads = blas->get_num_threads();
    if (s.host_threads != 1) blas->set_num_threads(1);
  }
  active_ = true;
}

BlasOnOneThread::~BlasOnOneThread() {
  if (!active_) return;
  ThreadSetting& s = Setting();
  std::lock_guard<std::mutex> lock(s.mutex);
  if (--s.running == 0 && s.host_threads != 1) Library().set_num_threads(s.host_threads);
}

void MultiplyTransposed(const float* a, int rows, int lda, const float* b, int cols, int ldb,
                        int width, float* c, int ldc) {
  if (rows <= 0 || cols <= 0) return;
  const OpenBlas& blas = Library();
  const BlasOnOneThread one_thread;
  const auto call = [&] {
    blas.sgemm(CblasRowMajor, CblasNoTrans, CblasTrans, rows, cols, width, 1.0f, a, lda, b, ldb,
               0.0f, c, ldc);
  };
  if (blas.overlap) {
    call();
  } else {
    std::lock_guard<std::mutex> lock(OneAtATime());
    call();
  }
}

std::string BlasDescription() {
  const OpenBlas& blas = Library();
  const int parallel = blas.get_parallel();
  return std::string(blas.get_config()) + "; kernels " + blas.get_corename() +
         (blas.chosen.empty() ? ""
                              : " (OPENBLAS_CORETYPE set by OpenABLE: the library did not "
                                "recognise this CPU)") +
         "; " +
         (parallel == 1   ? "pthreads"
          : parallel == 2 ? "OpenMP"
                          : "single-threaded") +
         " build";
}

}  // namespace openable
