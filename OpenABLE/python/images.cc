// Images and descriptor names: read_image, list_images, to_gray8, descriptor_names.
#include <pybind11/stl.h>

#include <opencv2/imgproc.hpp>

#include "OpenABLE/image/preprocess.h"
#include "OpenABLE/io/frame_source.h"
#include "OpenABLE/python/common.h"
#include "descriptors/registry.h"

namespace openable::python {

void RegisterImages(py::module_& m) {
  // The names and what each is come from the descriptors' registry.
  static const std::string names_doc =
      "descriptor_names() -> list[str]\n\nNames of the descriptors this build provides, in the "
      "order shown to users, any case wherever a descriptor is asked for: " +
      DescriptorHelp() +
      ". D-LDB needs a grey + disparity image (stereo) and is not usable through describe().";
  m.def("descriptor_names", &RegisteredDescriptorNames, names_doc.c_str());

  m.def(
      "unavailable_descriptors",
      [] {
        py::dict d;
        for (const auto& [name, reason] : UnavailableDescriptors()) d[py::str(name)] = reason;
        return d;
      },
      R"doc(unavailable_descriptors() -> dict[str, str]

Descriptors of the original OpenABLE that this build cannot provide, each with the reason
(SURF: patented, absent from Debian's OpenCV).)doc");

  m.def(
      "read_image",
      [](const py::object& path_object, const std::string& color_order) {
        const std::string path = FileSystemPath(path_object, "path");
        const bool rgb = IsRgbOrder(color_order);
        cv::Mat image;
        {
          py::gil_scoped_release release;
          image = ReadImageFile(path);
          if (rgb && image.channels() == 3) cv::cvtColor(image, image, cv::COLOR_BGR2RGB);
        }
        return ToNumpy(image);
      },
      py::arg("path"), py::arg("color_order") = "bgr",
      R"doc(read_image(path, color_order="bgr") -> numpy.ndarray

Reads one image file exactly as Test_OpenABLE reads the frames of a folder (PNG, JPEG, PNM
and BMP by OpenCV's codecs after OpenABLE's own integrity checks; TIFF and the rest by
OpenImageIO).

Args:
    path (str | os.PathLike | bytes): the image file (a pathlib.Path is fine).
    color_order (str): "bgr" (OpenCV's order, what the library uses) or "rgb" (for
        matplotlib's imshow, PIL, imageio); only colour images are affected.

Returns:
    numpy.ndarray: float32 in [0, 1] whatever the bit depth of the file, shape (H, W) for a
    grey image or (H, W, 3) in the order asked for a colour one (alpha dropped). This is the
    form describe(), describe_images() and OnlineDetector.add_frame() take (give them the same
    color_order).

Raises:
    openable.InputError: one line naming the file when it is missing, corrupt, truncated or
    not an image.)doc");

  m.def(
      "list_images",
      [](const py::object& folder, const std::string& extension) {
        // Names are bytes on Linux: decoded as Python decodes file names (surrogateescape), so
        // a name that is not UTF-8 still comes back, and read_image() takes it as it is.
        py::list out;
        for (const std::string& p : ListImages(FileSystemPath(folder, "folder"), extension))
          out.append(py::reinterpret_steal<py::object>(PyUnicode_DecodeFSDefault(p.c_str())));
        return out;
      },
      py::arg("folder"), py::arg("extension") = "",
      R"doc(list_images(folder, extension="") -> list[str]

The image files of a folder in natural order of their names (img2 before img10), as a run of
Test_OpenABLE takes them (not recursive).

Args:
    folder (str | os.PathLike | bytes): the folder.
    extension (str): keep only files with this extension ("png", case-insensitive, with or
        without the dot); empty keeps every supported image type.

Returns:
    list[str]: full paths.

Raises:
    openable.InputError: the folder is missing, not a folder, or holds no matching image.)doc");

  m.def(
      "to_gray8",
      [](const py::object& image, const std::string& color_order) {
        MatView v = Image(image, "image", IsRgbOrder(color_order));
        cv::Mat1b gray;
        {
          py::gil_scoped_release release;
          cv::Mat frame = v.mat;
          if (frame.depth() == CV_8U) frame.convertTo(frame, CV_32F, 1.0 / 255.0);
          gray = ToGray8(frame);
        }
        return ToNumpy(gray);
      },
      py::arg("image"), py::arg("color_order") = "bgr",
      R"doc(to_gray8(image, color_order="bgr") -> numpy.ndarray

The grey 8-bit image every monocular descriptor describes: OpenCV's luma weights
(0.299 R + 0.587 G + 0.114 B) on the [0, 1] image, times 255, rounded.

Args:
    image (numpy.ndarray): (H, W) grey or (H, W, 3) colour; uint8 (0-255) or float32 (0-1).
    color_order (str): channel order of a colour image, "bgr" (OpenCV's) or "rgb".

Returns:
    numpy.ndarray: uint8, shape (H, W).)doc");
}

}  // namespace openable::python
