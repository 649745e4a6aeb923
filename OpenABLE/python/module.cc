// The Python module `openable` (docs/python.md).
#include <stdexcept>

#include <opencv2/core.hpp>

#include "OpenABLE/base/error.h"
#include "OpenABLE/base/threading.h"
#include "OpenABLE/base/version.h"
#include "OpenABLE/python/common.h"

namespace {

// Ctrl-C during a long call: Python runs its SIGINT handler only between bytecodes, and the
// call runs in C++ with the GIL released. The library's loops call this between items
// (SetInterruptCheck, OpenABLE/base/threading.h): it takes the GIL, lets Python run pending
// signal handlers, and stops the computation with their exception (KeyboardInterrupt), which
// reaches the caller once the C++ stack has unwound.
void CheckPythonSignals() {
  if (!Py_IsInitialized()) return;
  pybind11::gil_scoped_acquire gil;
  if (PyErr_CheckSignals() != 0) throw pybind11::error_already_set();
}

}  // namespace

PYBIND11_MODULE(openable, m) {
  namespace py = pybind11;
  // Every docstring starts with its own signature, written for readers (numpy.ndarray rather
  // than pybind11's "object"); pybind11's generated one would repeat it.
  py::options options;
  options.disable_function_signatures();
  m.doc() = R"doc(OpenABLE: visual place recognition and loop-closure detection (docs/python.md).

Images are NumPy arrays: (H, W) grey or (H, W, 3) BGR, uint8 (0-255) or float32 (0-1), as
read_image() gives them. Descriptor rows are uint8 (binary descriptors, Hamming distance) or
float32 (vector descriptors, L2). Distance matrices are float32 NumPy arrays that own the C++
result (no copy); contiguous input arrays are read in place. Long computations release the GIL.

Parts:
  descriptors   descriptor_names, describe, describe_images, read_image, list_images, to_gray8
  matching      hamming_distances, l2_distances, l1_distances, sequence_distances,
                distance_matrix, contrast_enhancement, normalize_by_max, threshold_matrix,
                best_matches, read_matrix
  evaluation    evaluate -> EvaluationResult (figures and Curve objects); sweep ->
                SweepResult (every combination of a few keys, ranked)
  online        OnlineDetector (loop candidates frame by frame)
  snaps         openable.snaps: trajectories, loops, discounted update, pose graph, errors

Errors: bad input raises openable.InputError (a ValueError) with the same one-line message as
the command-line programs; other invalid arguments raise ValueError.)doc";
  m.attr("__version__") = openable::kVersion;

  py::register_exception<openable::InputError>(m, "InputError", PyExc_ValueError);
  m.attr("InputError").attr("__doc__") =
      "Bad input (a file, an option, a value): one line naming it, the value and what was "
      "expected. A subclass of ValueError.";
  // A broken precondition of the C++ library on arguments given from Python (a wrong shape, a
  // bad index) is an invalid value here.
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const std::out_of_range&) {
      throw;  // pybind11's own translation: IndexError
    } catch (const std::logic_error& e) {
      PyErr_SetString(PyExc_ValueError, e.what());
    } catch (const cv::Exception& e) {
      // OpenCV's own text spans lines and names its source file (alloc.cpp): one line here,
      // and a failed allocation is a MemoryError, as NumPy's are.
      if (e.code == cv::Error::StsNoMem) {
        PyErr_SetString(PyExc_MemoryError,
                        ("not enough memory for this request (OpenCV could not allocate: " +
                         openable::Trim(e.err) + ")").c_str());
      } else {
        PyErr_SetString(PyExc_RuntimeError,
                        ("OpenCV error in " + e.func + ": " + openable::Trim(e.err)).c_str());
      }
    }
  });

  openable::SetInterruptCheck(&CheckPythonSignals);
  openable::python::RegisterImages(m);
  openable::python::RegisterMatching(m);
  openable::python::RegisterEvaluation(m);
  openable::python::RegisterOnline(m);
  openable::python::RegisterSnaps(m);
  openable::python::RegisterSweep(m);
  // `import openable.snaps` and `from openable.snaps import ...` work like the attribute.
  py::module_::import("sys").attr("modules")["openable.snaps"] = m.attr("snaps");
}
