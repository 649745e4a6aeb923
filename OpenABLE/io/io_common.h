// Helpers shared by the frame sources and by the modules loaded at run time (module_loader.h).
// Internal to OpenABLE/io; not part of the public interface.
#pragma once

#include <string>

namespace openable::io_internal {

inline constexpr const char* kExpectedFolder = "expected a folder of images";
inline constexpr const char* kExpectedImage = "expected a PNG/JPEG/TIFF/PGM/PPM/BMP image";
inline constexpr const char* kExpectedVideo = "expected a video file readable by FFmpeg/GStreamer";

// The first non-blank line of a library's error text, trimmed, without control characters.
std::string FirstLine(const std::string& text);

// Lower-case extension of a file name, without the dot ("" when it has none).
std::string ExtensionOf(const std::string& file_name);

// "png" for "png", ".png", ".PNG"; empty stays empty.
std::string NormalizeExtension(const std::string& extension);

// Resolves [first, last) (last = -1: to the end) against `count` items and returns the end;
// the error names the items (e.g. "images") and `where` they are (e.g. "folder \"/x\"").
int ResolveRangeEnd(int first, int last, int count, const std::string& what_plural,
                    const std::string& what_singular, const std::string& where);

// Throws std::logic_error when i is outside [0, size).
void CheckIndex(int i, int size, const char* where);

}  // namespace openable::io_internal
