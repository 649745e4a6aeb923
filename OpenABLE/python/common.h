// Shared pieces of the Python module `openable` (docs/python.md): NumPy arrays viewed as
// cv::Mat headers, cv::Mat results handed to NumPy without copies, and the parsing of the
// string options that the bindings take instead of C++ enums.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <cstddef>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <string>
#include <utility>
#include <vector>

#include "OpenABLE/base/enum_names.h"
#include "OpenABLE/base/error.h"
#include "OpenABLE/base/strings.h"

namespace openable::python {

namespace py = pybind11;

// A NumPy array seen as a cv::Mat. `mat` points into `owner`'s memory when the array's layout
// allows it (elements of a row adjacent, rows at a positive stride, aligned, native byte
// order), else into a contiguous converted copy that `owner` holds. `owner` must outlive every
// use of `mat`.
struct MatView {
  cv::Mat mat;
  py::array owner;
  bool copied = false;
};

// Element types a view may take.
enum class Elements {
  kUint8,           // uint8 only (binary descriptor rows: any other type is refused)
  kFloat32,         // any real or integer type, converted to float32 when it is not
  kUint8OrFloat32,  // uint8 kept, float32 kept, any other real type converted to float32
};

// A 2-D matrix (a 1-D array is one row). `what` names the argument in errors (ValueError).
MatView Matrix2D(const py::handle& object, Elements elements, const char* what);

// The `color_order` argument of the functions that take or return colour images: "bgr"
// (OpenCV's order, the library's own) gives false, "rgb" (matplotlib, PIL, imageio) true;
// anything else is a ValueError.
bool IsRgbOrder(const std::string& color_order);

// An image: (H, W) or (H, W, C) with C in {1, 3} (BGR, or RGB with `rgb`, then reordered to BGR
// in a copy), uint8 or float32 in [0, 1]; other real types are converted to float32. A 3-D
// array becomes a multi-channel cv::Mat (CV_8UC3, ...).
MatView Image(const py::handle& object, const char* what, bool rgb = false);

// Images of a Python sequence (list, tuple, or a 3-D/4-D array whose first axis is the image).
std::vector<MatView> Images(const py::handle& sequence, const char* what, bool rgb = false);

// The cv::Mat `m` (CV_8U or CV_32F, any channel count) as a NumPy array over the same memory:
// a capsule holds a cv::Mat header, so the buffer lives as long as the array. A matrix that
// does not own its memory (no cv::UMatData) is cloned first. `one_dimensional` gives a row
// vector the shape (cols,) instead of (1, cols).
py::array ToNumpy(const cv::Mat& m, bool one_dimensional = false);

// A NumPy array of doubles with the given shape, filled from `values` (copied).
py::array_t<double> DoubleArray(const std::vector<double>& values);

// The names of the properties of the bound class `cls` (def_readwrite, def_property,
// def_property_readonly), in the order they were bound.
std::vector<std::string> PropertyNames(const py::handle& cls);

// The properties of `object` as a dict, after COLMAP's MakeDataclass todict(): every property
// of its class (PropertyNames) whose value is a number, a string, a bool, None or a tuple, an
// object with its own to_dict() (converted), and, with `arrays`, a NumPy array (without, the
// per-query arrays of a result are left out).
py::dict PropertiesAsDict(const py::handle& object, bool arrays = false);

// Registration of each part of the module (one source file each).
// A path argument (str, bytes or os.PathLike) as the bytes the file system takes
// (os.fsencode: a name that is not UTF-8, decoded with surrogateescape, gets its bytes back).
// Throws ValueError naming `what` for anything else.
std::string FileSystemPath(const py::handle& path, const char* what);

// `message` as a UserWarning of the caller's line (warnings.warn; an exception when the
// warnings filter makes it one). Level 2: the caller of the module's one-line wrapper of every
// function (module.cc).
void Warn(const std::string& message);

// The default of Config.txt's `key` in the option table (ConfigTable over a default Config),
// as Config.txt writes it, unquoted: the programs' default, which the keywords that stand for
// the key share (their signatures and docstrings are filled from it).
std::string TableDefault(const char* key);

// `text` with each placeholder ("@tolerance@") of `values` replaced by its value: docstrings
// that show the option table's defaults.
template <std::size_t N>
std::string FillPlaceholders(std::string text,
                             const std::pair<const char*, std::string> (&values)[N]) {
  for (const auto& [name, value] : values) {
    const std::string placeholder = name;
    for (std::size_t at = text.find(placeholder); at != std::string::npos;
         at = text.find(placeholder, at))
      text.replace(at, placeholder.size(), value);
  }
  return text;
}

void RegisterImages(py::module_& m);
void RegisterMatching(py::module_& m);
void RegisterEvaluation(py::module_& m);
void RegisterOnline(py::module_& m);
void RegisterSnaps(py::module_& m);
void RegisterSweep(py::module_& m);

// A JSON value as Python objects: null -> None, numbers (NaN kept), strings, lists, dicts; an
// object's keys that are whole numbers ("1", "5") become ints, as recall@K's K.
py::object JsonToPython(const nlohmann::ordered_json& value);

// The message of an InputError that names Config.txt keys, with the Python arguments' names
// instead ("Ground_truth_radius: 0 ..." -> "radius: 0 ...", "(Ground_truth_type kitti)" ->
// "(truth_type kitti)"), wherever in the line they stand; empty when it names none.
std::string ArgumentNamesOf(const std::string& message);

// Runs `f`, whose option structs' Check() name Config.txt keys; such an InputError is re-thrown
// naming the Python arguments instead: the bindings validate through the same checks as the
// programs.
template <typename F>
auto WithArgumentNames(F f) {
  try {
    return f();
  } catch (const InputError& e) {
    const std::string renamed = ArgumentNamesOf(e.what());
    if (renamed.empty()) throw;
    throw InputError(renamed);
  }
}

}  // namespace openable::python
