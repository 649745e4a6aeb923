#include "OpenABLE/base/module_loader.h"

#include <dlfcn.h>
#include <link.h>

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <mutex>
#include <vector>

#include "OpenABLE/base/error.h"

namespace openable {
namespace {

// The file holding this code: the program, or the shared library OpenABLE was linked into.
// Empty when it cannot be told.
std::filesystem::path OwnFile(bool& is_program) {
  struct Query {
    std::uintptr_t address = 0;
    bool found = false;
    std::string name;
  } query;
  query.address = reinterpret_cast<std::uintptr_t>(&OwnFile);
  dl_iterate_phdr(
      [](dl_phdr_info* info, std::size_t, void* data) {
        Query& q = *static_cast<Query*>(data);
        for (int i = 0; i < info->dlpi_phnum; ++i) {
          const ElfW(Phdr)& segment = info->dlpi_phdr[i];
          if (segment.p_type != PT_LOAD) continue;
          const std::uintptr_t begin = info->dlpi_addr + segment.p_vaddr;
          if (q.address >= begin && q.address - begin < segment.p_memsz) {
            q.found = true;
            q.name = info->dlpi_name != nullptr ? info->dlpi_name : "";
            return 1;
          }
        }
        return 0;
      },
      &query);
  std::error_code ec;
  is_program = query.found && query.name.empty();  // the loader names the program ""
  if (!query.found) return {};
  if (is_program) return std::filesystem::read_symlink("/proc/self/exe", ec);
  std::filesystem::path file = std::filesystem::absolute(query.name, ec);
  return ec ? std::filesystem::path() : file;
}

// True when `file` lies inside `folder` (both made canonical as far as they exist).
bool IsInside(const std::filesystem::path& file, const std::filesystem::path& folder) {
  std::error_code ec;
  const std::string f = std::filesystem::weakly_canonical(file, ec).string();
  if (ec) return false;
  std::string d = std::filesystem::weakly_canonical(folder, ec).string();
  if (ec || d.empty()) return false;
  if (d.back() != '/') d += '/';
  return f.compare(0, d.size(), d) == 0;
}

// Where modules are searched, in order (docs/install.md): OPENABLE_MODULE_PATH; beside the
// file holding this code as installed (<prefix>/bin/../lib/openable for a program,
// <prefix>/lib/openable for a shared library, and <dir>/../../../openable for the Python
// extension in <prefix>/lib/python3.X/dist-packages/openable), whatever prefix it was
// installed to; the modules/ folder of a package installed by pip; then the
// build tree for a program of the build tree, the configured install folder for any other (so
// an installed program never picks up the modules of a later build).
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
  bool is_program = false;
  const std::filesystem::path own = OwnFile(is_program);
  bool in_build_tree = true, installed = true;  // both when the file is unknown
  if (!own.empty()) {
    const char* relative =
        is_program ? OPENABLE_MODULE_DIR_FROM_BINDIR : OPENABLE_MODULE_DIR_FROM_LIBDIR;
    folders.push_back((own.parent_path() / relative).lexically_normal().string());
    // The Python extension installed by cmake --install to
    // <libdir>/python3.X/dist-packages/openable/ (OPENABLE_PYTHON_INSTALL_DIR's default).
    if (!is_program)
      folders.push_back((own.parent_path() / "../../../openable").lexically_normal().string());
    // A package installed by pip (setup.py): the extension in openable/, the programs in
    // openable/bin/, the modules in openable/modules/.
    folders.push_back(
        (own.parent_path() / (is_program ? "../modules" : "modules")).lexically_normal().string());
    in_build_tree = IsInside(own, OPENABLE_BUILD_TREE);
    installed = !in_build_tree;
  }
  if (in_build_tree) folders.push_back(OPENABLE_MODULE_BUILD_DIR);
  if (installed) folders.push_back(OPENABLE_MODULE_INSTALL_DIR);
  std::vector<std::string> unique;
  for (const std::string& folder : folders) {
    if (std::find(unique.begin(), unique.end(), folder) == unique.end()) unique.push_back(folder);
  }
  return unique;
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
                   reasons +
                   "; expected it beside the build or installation of OpenABLE, or in "
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
