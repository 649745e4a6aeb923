#include "OpenABLE/python/common.h"

#include <cstdint>
#include <opencv2/imgproc.hpp>
#include <string>

#include "config/config.h"

namespace openable::python {
namespace {

std::string DtypeName(const py::array& a) { return py::str(a.dtype()).cast<std::string>(); }

std::string ShapeText(const py::array& a) {
  std::string s = "(";
  for (py::ssize_t d = 0; d < a.ndim(); ++d) {
    s += (d ? ", " : "") + std::to_string(a.shape(d));
  }
  return s + (a.ndim() == 1 ? ",)" : ")");
}

bool IsUint8(const py::array& a) { return py::isinstance<py::array_t<std::uint8_t>>(a); }
bool IsFloat32(const py::array& a) { return py::isinstance<py::array_t<float>>(a); }

// A C-contiguous copy of `a` with elements T. Through numpy.ascontiguousarray rather than
// pybind11's array_t::ensure: ensure() answers a failed allocation (a broadcast 100000 x 100000
// array, a memory limit) with an empty handle and clears the error, which then crashed the
// caller; NumPy raises MemoryError itself, and that reaches the user.
template <typename T>
py::array ContiguousCopy(const py::array& a) {
  // Leaked on purpose: a static py::object would be released after the interpreter has ended.
  static const py::object* const ascontiguousarray =
      new py::object(py::module_::import("numpy").attr("ascontiguousarray"));
  return (*ascontiguousarray)(a, py::dtype::of<T>()).template cast<py::array>();
}

// Float images are in [0, 1] (uint8 images in 0-255): a float image in 0-255 would saturate
// to white without a word. NaN is refused too.
void CheckFloatImage(const cv::Mat& image, const char* what) {
  const cv::Mat flat = image.reshape(1);
  for (int i = 0; i < flat.rows; ++i) {
    const float* row = flat.ptr<float>(i);
    for (int j = 0; j < flat.cols; ++j) {
      const float v = row[j];
      if (!(v >= 0.0f && v <= 1.0f))
        throw py::value_error(std::string(what) + ": float32 value " + FormatNumber(v) +
                              " at row " + std::to_string(i) +
                              "; expected values in [0, 1] (divide a 0-255 image by 255, or "
                              "pass it as uint8)");
    }
  }
}

// True when the memory of `a` (2-D or 3-D, elements of `item` bytes) can be described by a
// cv::Mat header: the last axes packed, rows at a positive multiple of the element size, the
// data aligned.
bool Viewable(const py::array& a, py::ssize_t item) {
  if (reinterpret_cast<std::uintptr_t>(a.data()) % static_cast<std::uintptr_t>(item) != 0)
    return false;
  py::ssize_t packed = item;                              // bytes of one row's packed inner part
  const py::ssize_t first_inner = a.ndim() == 1 ? 0 : 1;  // a 1-D array is one row
  for (py::ssize_t d = a.ndim() - 1; d >= first_inner; --d) {
    if (a.shape(d) > 1 && a.strides(d) != packed) return false;
    packed *= a.shape(d);
  }
  if (a.ndim() >= 2 && a.shape(0) > 1) {
    const py::ssize_t s0 = a.strides(0);
    if (s0 < packed || s0 % item != 0) return false;
  }
  return true;
}

// The row step of a viewable array.
std::size_t RowStep(const py::array& a, py::ssize_t packed) {
  if (a.ndim() >= 2 && a.shape(0) > 1) return static_cast<std::size_t>(a.strides(0));
  return static_cast<std::size_t>(packed);
}

MatView Wrap(py::array a, int depth, int channels, bool copied) {
  MatView v;
  v.copied = copied;
  const int rows = a.ndim() == 1 ? 1 : static_cast<int>(a.shape(0));
  const int cols = static_cast<int>(a.ndim() == 1 ? a.shape(0) : a.shape(1));
  const int type = CV_MAKETYPE(depth, channels);
  const py::ssize_t item = depth == CV_8U ? 1 : 4;
  if (rows == 0 || cols == 0) {
    v.mat = cv::Mat(rows, cols, type);
  } else {
    const std::size_t step = RowStep(a, item * cols * channels);
    v.mat = cv::Mat(rows, cols, type, const_cast<void*>(a.data()), step);
  }
  v.owner = std::move(a);
  return v;
}

}  // namespace

std::string FileSystemPath(const py::handle& path, const char* what) {
  // Leaked on purpose, as in ContiguousCopy.
  static const py::object* const fsencode =
      new py::object(py::module_::import("os").attr("fsencode"));
  try {
    return (*fsencode)(path).cast<std::string>();
  } catch (const py::error_already_set&) {
    throw py::value_error(std::string(what) + ": " +
                          py::str(py::type::of(path).attr("__name__")).cast<std::string>() +
                          "; expected a path (str, bytes or os.PathLike)");
  }
}

MatView Matrix2D(const py::handle& object, Elements elements, const char* what) {
  py::array a = py::array::ensure(object);
  if (!a) {
    throw py::value_error(std::string(what) +
                          ": expected a NumPy array (or a nested list of numbers)");
  }
  if (a.ndim() != 1 && a.ndim() != 2) {
    throw py::value_error(std::string(what) + ": array of shape " + ShapeText(a) +
                          "; expected a 2-D array (one row per item) or a 1-D row");
  }
  const char kind = a.dtype().kind();
  int depth = -1;
  if (IsUint8(a) && elements != Elements::kFloat32) {
    depth = CV_8U;
  } else if (elements == Elements::kUint8) {
    throw py::value_error(std::string(what) + ": dtype " + DtypeName(a) +
                          "; expected uint8 (the bytes of binary descriptor rows)");
  } else if (IsFloat32(a)) {
    depth = CV_32F;
  } else if (kind == 'f' ||
             (elements == Elements::kFloat32 && (kind == 'i' || kind == 'u' || kind == 'b'))) {
    return Wrap(ContiguousCopy<float>(a), CV_32F, 1, true);
  } else {
    throw py::value_error(std::string(what) + ": dtype " + DtypeName(a) +
                          "; expected uint8 (binary descriptors) or float32 (vector descriptors)");
  }
  const py::ssize_t item = depth == CV_8U ? 1 : 4;
  if (!Viewable(a, item)) {
    a = depth == CV_8U ? ContiguousCopy<std::uint8_t>(a) : ContiguousCopy<float>(a);
    return Wrap(std::move(a), depth, 1, true);
  }
  return Wrap(std::move(a), depth, 1, false);
}

bool IsRgbOrder(const std::string& color_order) {
  if (color_order == "bgr" || color_order == "BGR") return false;
  if (color_order == "rgb" || color_order == "RGB") return true;
  throw py::value_error("color_order: '" + color_order +
                        "'; expected 'bgr' (OpenCV's order, the default) or 'rgb' (matplotlib, "
                        "PIL, imageio)");
}

namespace {

// `v` with its three channels in BGR order: reordered into a new buffer when the array given
// was RGB (never in place: the caller's array is left as it was).
MatView ToBgr(MatView v, bool rgb) {
  if (!rgb || v.mat.channels() != 3) return v;
  cv::Mat bgr;
  cv::cvtColor(v.mat, bgr, cv::COLOR_RGB2BGR);
  return MatView{bgr, py::array(), true};
}

// The image as given (channels in the caller's order).
MatView ImageAsGiven(const py::handle& object, const char* what) {
  py::array a = py::array::ensure(object);
  if (!a) throw py::value_error(std::string(what) + ": expected an image as a NumPy array");
  const bool shape_ok = a.ndim() == 2 || (a.ndim() == 3 && (a.shape(2) == 1 || a.shape(2) == 3));
  if (!shape_ok) {
    throw py::value_error(std::string(what) + ": array of shape " + ShapeText(a) +
                          "; expected (H, W) grey or (H, W, 3) colour");
  }
  const int channels = a.ndim() == 3 ? static_cast<int>(a.shape(2)) : 1;
  int depth = -1;
  if (IsUint8(a)) {
    depth = CV_8U;
  } else if (IsFloat32(a)) {
    depth = CV_32F;
  } else if (a.dtype().kind() == 'f') {
    MatView v = Wrap(ContiguousCopy<float>(a), CV_32F, channels, true);
    CheckFloatImage(v.mat, what);
    return v;
  } else {
    throw py::value_error(std::string(what) + ": dtype " + DtypeName(a) +
                          "; expected uint8 (0-255) or float32 (0-1); scale other types first, "
                          "e.g. image / 65535.0 for 16-bit");
  }
  const bool copy = !Viewable(a, depth == CV_8U ? 1 : 4);
  if (copy) a = depth == CV_8U ? ContiguousCopy<std::uint8_t>(a) : ContiguousCopy<float>(a);
  MatView v = Wrap(std::move(a), depth, channels, copy);
  if (depth == CV_32F) CheckFloatImage(v.mat, what);
  return v;
}

}  // namespace

MatView Image(const py::handle& object, const char* what, bool rgb) {
  return ToBgr(ImageAsGiven(object, what), rgb);
}

std::vector<MatView> Images(const py::handle& sequence, const char* what, bool rgb) {
  std::vector<MatView> out;
  if (py::isinstance<py::array>(sequence)) {
    const py::array a = py::reinterpret_borrow<py::array>(sequence);
    if (a.ndim() != 3 && a.ndim() != 4) {
      throw py::value_error(std::string(what) + ": array of shape " + ShapeText(a) +
                            "; expected a stack of images (N, H, W) or (N, H, W, 3), or a list");
    }
  } else if (!py::isinstance<py::sequence>(sequence) || py::isinstance<py::str>(sequence)) {
    throw py::value_error(std::string(what) + ": expected a list of images (NumPy arrays)");
  }
  const py::sequence items = py::reinterpret_borrow<py::sequence>(sequence);
  out.reserve(items.size());
  for (std::size_t i = 0; i < items.size(); ++i) {
    const std::string name = std::string(what) + "[" + std::to_string(i) + "]";
    out.push_back(Image(items[i], name.c_str(), rgb));
  }
  return out;
}

py::array ToNumpy(const cv::Mat& input, bool one_dimensional) {
  cv::Mat m = input;
  if (!m.empty() && m.u == nullptr) m = m.clone();
  py::dtype dtype;
  switch (m.depth()) {
    case CV_8U:
      dtype = py::dtype::of<std::uint8_t>();
      break;
    case CV_32F:
      dtype = py::dtype::of<float>();
      break;
    case CV_64F:
      dtype = py::dtype::of<double>();
      break;
    case CV_32S:
      dtype = py::dtype::of<std::int32_t>();
      break;
    default:
      throw std::logic_error("ToNumpy: unsupported depth " + std::to_string(m.depth()));
  }
  const py::ssize_t item = static_cast<py::ssize_t>(m.elemSize1());
  const py::ssize_t channels = m.channels();
  std::vector<py::ssize_t> shape, strides;
  if (one_dimensional) {
    if (m.rows > 1 || channels != 1) throw std::logic_error("ToNumpy: not a row");
    shape = {m.cols};
    strides = {item};
  } else {
    shape = {m.rows, m.cols};
    strides = {static_cast<py::ssize_t>(m.empty() ? m.cols * item * channels : m.step[0]),
               item * channels};
    if (channels > 1) {
      shape.push_back(channels);
      strides.push_back(item);
    }
  }
  if (m.empty()) return py::array(dtype, shape);
  auto* keep = new cv::Mat(m);
  py::capsule base(keep, [](void* p) { delete static_cast<cv::Mat*>(p); });
  return py::array(dtype, shape, strides, keep->data, base);
}

py::array_t<double> DoubleArray(const std::vector<double>& values) {
  py::array_t<double> a(static_cast<py::ssize_t>(values.size()));
  std::copy(values.begin(), values.end(), a.mutable_data());
  return a;
}

std::vector<std::string> PropertyNames(const py::handle& cls) {
  std::vector<std::string> names;
  const py::object property = py::module_::import("builtins").attr("property");
  for (const auto item : py::dict(cls.attr("__dict__")))
    if (py::isinstance(item.second, property)) names.push_back(item.first.cast<std::string>());
  return names;
}

py::dict PropertiesAsDict(const py::handle& object, bool arrays) {
  py::dict out;
  for (const std::string& name : PropertyNames(py::type::of(object))) {
    const py::object value = object.attr(name.c_str());
    if (py::hasattr(value, "to_dict")) {
      out[name.c_str()] = value.attr("to_dict")();
    } else if (value.is_none() || py::isinstance<py::bool_>(value) ||
               py::isinstance<py::int_>(value) || py::isinstance<py::float_>(value) ||
               py::isinstance<py::str>(value) || py::isinstance<py::tuple>(value) ||
               py::isinstance<py::dict>(value) || (arrays && py::isinstance<py::array>(value))) {
      out[name.c_str()] = value;
    }
  }
  return out;
}

void Warn(const std::string& message) {
  if (PyErr_WarnEx(PyExc_UserWarning, message.c_str(), 2) != 0) throw py::error_already_set();
}

std::string TableDefault(const char* key) {
  std::string v = ConfigValueText(Config(), key);
  if (v.size() >= 2 && v.front() == '"' && v.back() == '"') v = v.substr(1, v.size() - 2);
  return v;
}

std::string ArgumentNamesOf(const std::string& what) {
  static const std::pair<const char*, const char*> kNames[] = {
      {"Ground_truth_radius:", "radius:"},
      {"Ground_truth_heading:", "heading_limit:"},
      {"Ground_truth_min_gap:", "min_frame_gap:"},
      {"Ground_truth_axes:", "axes:"},
      {"Ground_truth_base:", "base:"},
      {"Initial_image:", "first_frame:"},
      {"Tolerance:", "tolerance:"},
      {"Exclusion:", "exclusion:"},
      {"Vicinity:", "vicinity:"},
      {"Ground_truth_2:", "truth_file_2:"},
      {"Ground_truth:", "truth_file:"},
      {"Ground_truth_type:", "truth_type:"},
      {"Match_score_window:", "score_window:"},
      {"Match_threshold:", "accept_threshold:"},
      {"Match_consistency:", "accept_consistency:"},
      {"Image_sequences:", "sequence_length:"},
      {"Evaluation_protocol:", "protocol:"},
      {"Ground_truth_soft:", "truth_file_soft:"}};
  const auto word = [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) != 0 || c == '_';
  };
  std::string message = what;
  bool renamed = false;
  for (const auto& [key_colon, name_colon] : kNames) {
    const std::string key(key_colon, std::strlen(key_colon) - 1);
    const std::string name(name_colon, std::strlen(name_colon) - 1);
    for (std::size_t at = message.find(key); at != std::string::npos; at = message.find(key, at)) {
      const std::size_t end = at + key.size();
      if ((at > 0 && word(message[at - 1])) || (end < message.size() && word(message[end]))) {
        at = end;
        continue;
      }
      message.replace(at, key.size(), name);
      at += name.size();
      renamed = true;
    }
  }
  return renamed ? message : std::string();
}

py::object JsonToPython(const nlohmann::ordered_json& v) {
  switch (v.type()) {
    case nlohmann::ordered_json::value_t::null:
      return py::none();
    case nlohmann::ordered_json::value_t::boolean:
      return py::bool_(v.get<bool>());
    case nlohmann::ordered_json::value_t::number_integer:
      return py::int_(v.get<std::int64_t>());
    case nlohmann::ordered_json::value_t::number_unsigned:
      return py::int_(v.get<std::uint64_t>());
    case nlohmann::ordered_json::value_t::number_float:
      return py::float_(v.get<double>());
    case nlohmann::ordered_json::value_t::string:
      return py::str(v.get<std::string>());
    case nlohmann::ordered_json::value_t::array: {
      py::list out;
      for (const auto& item : v) out.append(JsonToPython(item));
      return std::move(out);
    }
    case nlohmann::ordered_json::value_t::object: {
      py::dict out;
      for (const auto& [key, item] : v.items()) {
        const bool whole = !key.empty() && key.size() < 10 &&
                           key.find_first_not_of("0123456789") == std::string::npos;
        if (whole)
          out[py::int_(std::stoi(key))] = JsonToPython(item);
        else
          out[py::str(key)] = JsonToPython(item);
      }
      return std::move(out);
    }
    default:
      throw std::logic_error("JsonToPython: a value of no JSON type");
  }
}

}  // namespace openable::python
