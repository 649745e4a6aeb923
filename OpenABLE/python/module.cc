// The extension openable._openable (docs/python.md), whose contents the package openable
// (OpenABLE/python/openable/__init__.py) re-exports.
#include <pybind11/eval.h>

#include <opencv2/core.hpp>
#include <stdexcept>

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

PYBIND11_MODULE(_openable, m) {
  namespace py = pybind11;
  // Classes, functions and messages name the package users import (openable.Curve, not
  // openable._openable.Curve); set before anything is defined, since classes and the snaps
  // submodule take their names from it.
  m.attr("__name__") = "openable";
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
                         openable::Trim(e.err) + ")")
                            .c_str());
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
  // pybind11 reports arguments of the wrong type (a string for patch_size, an integer beyond
  // 64 bits) as a TypeError of ten lines listing every overload and echoing the arguments,
  // arrays included. Every public function and method is wrapped (functools.wraps keeps its
  // name, docstring and signature) so that this error is one line naming the function and what
  // it takes.
  py::exec(R"py(
import functools as _functools
import inspect as _inspect

def _one_line(function, qualified):
    @_functools.wraps(function)
    def wrapper(*args, **kwargs):
        try:
            return function(*args, **kwargs)
        except TypeError as error:
            text = str(error)
            if "incompatible function arguments" not in text and                "incompatible constructor arguments" not in text:
                raise
            lines = [line.strip() for line in text.splitlines()]
            expected = next((line[3:] for line in lines if line.startswith("1. ")), "")
            raise TypeError("%s: arguments of the wrong type; expected %s (see help(%s))"
                            % (qualified, expected, qualified)) from None
    return wrapper

def _wrap_module(module):
    for name in dir(module):
        if name.startswith("_"):
            continue
        obj = getattr(module, name)
        qualified = module.__name__ + "." + name
        if _inspect.isbuiltin(obj):
            setattr(module, name, _one_line(obj, qualified))
        elif _inspect.isclass(obj) and not issubclass(obj, BaseException):
            for member in list(vars(obj)):
                if member.startswith("_") and member != "__init__":
                    continue
                attribute = vars(obj)[member]
                where = qualified + "." + member
                if type(attribute).__name__ == "instancemethod":
                    setattr(obj, member, _one_line(getattr(obj, member), where))
                elif isinstance(attribute, property) and attribute.fset is not None:
                    setattr(obj, member, property(attribute.fget,
                                                  _one_line(attribute.fset, where),
                                                  attribute.fdel, attribute.__doc__))
)py",
           m.attr("__dict__"));
  m.attr("_wrap_module")(m);
  m.attr("_wrap_module")(m.attr("snaps"));

  // `import openable.snaps` and `from openable.snaps import ...` work like the attribute.
  py::module_::import("sys").attr("modules")["openable.snaps"] = m.attr("snaps");
}
