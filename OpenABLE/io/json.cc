#include "OpenABLE/io/json.h"

#include <cmath>
#include <cstdint>
#include <cstdlib>

#include "OpenABLE/base/strings.h"

namespace openable::json {
namespace {

// A string literal: the text shown by ToValidUtf8, then nlohmann's escaping (quotes, backslashes,
// control characters as \n, \t or \u0001). The text is valid UTF-8 by then; `replace` only
// keeps a document from ever failing on a string.
std::string Literal(const std::string& s) {
  return Json(ToValidUtf8(s)).dump(-1, ' ', false, Json::error_handler_t::replace);
}

// `v` with every string and name shown by ToValidUtf8 (DumpLine).
Json ShownStrings(const Json& v) {
  if (v.is_string()) return ToValidUtf8(v.get_ref<const std::string&>());
  if (v.is_array()) {
    Json out = Json::array();
    for (const Json& e : v) out.push_back(ShownStrings(e));
    return out;
  }
  if (v.is_object()) {
    Json out = Json::object();
    for (auto it = v.begin(); it != v.end(); ++it)
      out[ToValidUtf8(it.key())] = ShownStrings(it.value());
    return out;
  }
  return v;
}

void Write(const Json& v, int depth, std::string& out) {
  const bool object = v.is_object();
  if (object || v.is_array()) {
    if (v.empty()) {
      out += object ? "{}" : "[]";
      return;
    }
    const std::string inner(2 * (depth + 1), ' ');
    out += object ? "{\n" : "[\n";
    bool first = true;
    for (auto it = v.begin(); it != v.end(); ++it) {
      out += first ? "" : ",\n";
      first = false;
      out += inner;
      if (object) out += Literal(it.key()) + ": ";
      Write(it.value(), depth + 1, out);
    }
    out += "\n" + std::string(2 * depth, ' ') + (object ? "}" : "]");
  } else if (v.is_number_float()) {
    const double x = v.get<double>();
    out += std::isfinite(x) ? FormatNumber(x, 9) : "null";
  } else if (v.is_string()) {
    out += Literal(v.get_ref<const std::string&>());
  } else {
    out += v.dump();  // null, true, false, integers
  }
}

}  // namespace

Json Number(double value, int significant) {
  if (!std::isfinite(value)) return nullptr;
  const std::string text = FormatNumber(value, significant);
  // Without a point or an exponent the text is an integer of at most `significant` digits
  // (%g switches to an exponent beyond them): stored as one, it is written without a point
  // whatever the writer. "-0" stays a double, to be written as %g writes it.
  if (text.find_first_of(".e") == std::string::npos && text != "-0" && significant <= 18)
    return static_cast<std::int64_t>(std::strtoll(text.c_str(), nullptr, 10));
  return std::strtod(text.c_str(), nullptr);
}

Json Strings(const std::vector<std::string>& items) {
  Json out = Json::array();
  for (const std::string& s : items) out.push_back(s);
  return out;
}

std::string Dump(const Json& document) {
  std::string out;
  Write(document, 0, out);
  return out + "\n";
}

std::string DumpLine(const Json& document) {
  return ShownStrings(document).dump(-1, ' ', false, Json::error_handler_t::replace);
}

}  // namespace openable::json
