// Parts of OpenABLE that need heavy libraries are built as modules loaded on first use (dlopen):
// openable_oiio, _video, _gui, _codecs (OpenCV imgcodecs; PNG and JPEG need no module), _mpi,
// _faiss, _dnn and _rosbag. Debian's OpenImageIO and videoio each pull in hundreds of shared
// libraries (FFmpeg, GDAL, Qt, ...) bound at start-up, a cost every run paid before main()
// (docs/benchmarks.md, "End-to-end run times and start-up"). Modules are searched in
// OPENABLE_MODULE_PATH, beside the installed program or package, then in the build tree or the
// configured prefix (docs/install.md).
#pragma once

#include <string>

namespace openable {

// The address of `symbol` in module `name` (e.g. "video" loads libopenable_video.so), loading
// the module on first use; thread-safe. Throws InputError naming the module, the folders
// searched and the loader's reason when it cannot be loaded (e.g. a partial installation).
void* ModuleSymbol(const std::string& name, const char* symbol);

}  // namespace openable
