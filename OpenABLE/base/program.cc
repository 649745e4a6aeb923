#include "OpenABLE/base/program.h"

#include <malloc.h>

#include <exception>
#include <iostream>

#include "OpenABLE/base/error.h"
#include "OpenABLE/base/strings.h"

namespace openable {

void KeepFrameBuffersOnTheHeap() {
  mallopt(M_MMAP_THRESHOLD, 256 << 20);
  mallopt(M_TRIM_THRESHOLD, 1 << 30);
}

int RunProgram(const std::string& program, const std::function<int()>& body) {
  try {
    return body();
  } catch (const InputError& e) {
    std::cerr << program << ": error: " << ToValidUtf8(e.what()) << "\n";
    return kExitInputError;
  } catch (const std::exception& e) {
    std::cerr << program << ": internal error (please report): " << ToValidUtf8(e.what()) << "\n";
    return kExitInternalError;
  }
}

}  // namespace openable
