// The one table of descriptor names: descriptors are created only
// here, from their configured name. Not self-registering: an explicit table.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "descriptors/descriptor.h"

namespace openable {

// Names that CreateDescriptor accepts, in the order shown to users.
std::vector<std::string> RegisteredDescriptorNames();

// Each registered name with what it is and how its rows are compared, then the unavailable
// names with their reasons: the help of Image_descriptor and of Python's descriptor_names().
std::string DescriptorHelp();

// Names the original OpenABLE knew that this build cannot provide, each with the reason
// (SURF: patented, absent from Debian's OpenCV).
std::vector<std::pair<std::string, std::string>> UnavailableDescriptors();

// Creates the descriptor `name` (case-insensitive). Throws InputError naming the value and
// listing the valid names when `name` is unknown or unavailable, or when `options` do not
// suit the descriptor (e.g. a HOG patch that is not a multiple of 8).
std::unique_ptr<Descriptor> CreateDescriptor(const std::string& name,
                                             const DescriptorOptions& options);
// The same with the name of `options` (the key Image_descriptor).
std::unique_ptr<Descriptor> CreateDescriptor(const DescriptorOptions& options);

// The descriptors an Image_descriptor value names: one name, or several joined by "+" or ","
// (e.g. "HOG+LDB": a fusion of their matrices), each trimmed and in upper case. Throws
// InputError naming Image_descriptor and the value on an empty item, a name given twice, or an
// unknown or unavailable name (as CreateDescriptor).
std::vector<std::string> DescriptorList(const std::string& value);

}  // namespace openable
