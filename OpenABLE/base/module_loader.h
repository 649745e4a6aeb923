// Parts of OpenABLE that need heavy libraries are built as modules loaded on first use
// (dlopen), so that a run that does not need them does not pay for loading them:
//
//   openable_oiio   OpenImageIO reading (TIFF and the files OpenCV's decoders refuse)
//   openable_video  OpenCV videoio (FFmpeg, GStreamer)
//   openable_gui    OpenCV highgui (Show_images)
//   openable_codecs OpenCV imgcodecs (PGM/PPM and BMP frames, matrix images other than PNG;
//                   PNG and JPEG are decoded and PNG written in the program itself)
//   openable_mpi    Open MPI, for runs spread over processes (OpenABLE/cluster/cluster.h)
//   openable_faiss  FAISS, approximate search (matching/search/approximate.h)
//   openable_dnn    OpenCV dnn (ONNX networks of the ONNX descriptor, descriptors/onnx.h)
//   openable_rosbag ROS 1 bags (rosbag_storage: Boost, lz4, bz2, the ROS plugin loader)
//
// Debian's OpenImageIO and videoio pull in about 250 shared libraries each (FFmpeg, GDAL,
// OpenVDB, Qt, ...), all bound at start-up (BIND_NOW): linking them into Test_OpenABLE cost
// 0.3 s of every run before main(), more than the whole computation on Nordland.
//
// Modules are searched in the folders of the environment variable OPENABLE_MODULE_PATH
// (colon-separated), then beside the program (or shared library) holding this code as
// installed (<prefix>/lib/openable, whatever prefix it was installed to) or as pip installs
// the Python package (openable/modules/ beside openable/bin/), then in the build
// tree's modules/ for a program of the build tree, or in the configured prefix's lib/openable
// for any other program (docs/install.md).
#pragma once

#include <string>

namespace openable {

// The address of `symbol` in module `name` (e.g. "video" loads libopenable_video.so), loading
// the module on first use; thread-safe. Throws InputError naming the module, the folders
// searched and the loader's reason when it cannot be loaded (e.g. a partial installation).
void* ModuleSymbol(const std::string& name, const char* symbol);

}  // namespace openable
