#include "OpenABLE/io/json.h"

#include <cmath>
#include <cstdint>
#include <cstdlib>

#include "OpenABLE/base/strings.h"

namespace openable::json {

Json Number(double value, int significant) {
  if (!std::isfinite(value)) return nullptr;
  const std::string text = FormatNumber(value, significant);
  // Without a point or an exponent the text is an integer of at most `significant` digits
  // (%g switches to an exponent beyond them), which fits in 64 bits up to 18 digits.
  if (text.find_first_of(".e") == std::string::npos && significant <= 18)
    return static_cast<std::int64_t>(std::strtoll(text.c_str(), nullptr, 10));
  return std::strtod(text.c_str(), nullptr);
}

Json Strings(const std::vector<std::string>& items) {
  Json out = Json::array();
  for (const std::string& s : items) out.push_back(s);
  return out;
}

std::string Dump(const Json& document) {
  return document.dump(2, ' ', false, nlohmann::ordered_json::error_handler_t::replace) + "\n";
}

}  // namespace openable::json
