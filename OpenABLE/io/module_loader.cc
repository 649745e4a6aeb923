#include "OpenABLE/io/module_loader.h"

#include <dlfcn.h>

#include <cstdlib>
#include <filesystem>
#include <map>
#include <mutex>
#include <vector>

#include "OpenABLE/base/error.h"

namespace openable {
namespace {

std::vector<std::string> SearchFolders() {
  std::vector<std::string> folders;
  if (const char* env = std::getenv("OPENABLE_MODULE_PATH")) {
    std::string path = env;
    std::size_t begin = 0;
    while (begin <= path.size()) {
      std::size_t end = path.find(':', begin);
      if (end == std::string::npos) end = path.size();
      if (end > begin) folders.push_back(path.substr(begin, end - begin));
      begin = end + 1;
    }
  }
  folders.push_back(OPENABLE_MODULE_BUILD_DIR);
  folders.push_back(OPENABLE_MODULE_INSTALL_DIR);
  return folders;
}

void* Load(const std::string& name) {
  const std::string file = "libopenable_" + name + ".so";
  std::string reasons;
  std::string searched;
  for (const std::string& folder : SearchFolders()) {
    searched += (searched.empty() ? "" : ", ") + folder;
    const std::string path = (std::filesystem::path(folder) / file).string();
    std::error_code ec;
    if (!std::filesystem::exists(path, ec)) continue;
    // RTLD_LOCAL: the module's libraries stay out of the global symbol scope.
    if (void* handle = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL)) return handle;
    const char* why = dlerror();
    reasons += std::string("; ") + (why != nullptr ? why : "unknown dlopen error");
  }
  throw InputError("OpenABLE module " + Quoted(file) + " cannot be loaded (searched " + searched +
                   reasons + "; expected it beside the build or installation of OpenABLE, or in "
                   "a folder of OPENABLE_MODULE_PATH)");
}

}  // namespace

void* ModuleSymbol(const std::string& name, const char* symbol) {
  static std::mutex mutex;
  static std::map<std::string, void*> handles;  // never closed: modules live until exit
  std::lock_guard<std::mutex> lock(mutex);
  void*& handle = handles[name];
  if (handle == nullptr) handle = Load(name);
  dlerror();
  void* address = dlsym(handle, symbol);
  if (address == nullptr) {
    throw InputError("OpenABLE module " + Quoted("libopenable_" + name + ".so") +
                     " has no symbol " + Quoted(symbol) +
                     " (expected a module from the same build as this program)");
  }
  return address;
}

}  // namespace openable
