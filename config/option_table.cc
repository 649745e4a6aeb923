#include "config/option_table.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <map>
#include <sstream>

#include "OpenABLE/base/error.h"
#include "OpenABLE/base/strings.h"

namespace openable {
namespace {

// Edit distance, for "did you mean".
int Levenshtein(const std::string& a, const std::string& b) {
  std::vector<int> prev(b.size() + 1), cur(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) prev[j] = static_cast<int>(j);
  for (size_t i = 1; i <= a.size(); ++i) {
    cur[0] = static_cast<int>(i);
    for (size_t j = 1; j <= b.size(); ++j)
      cur[j] = std::min({prev[j] + 1, cur[j - 1] + 1, prev[j - 1] + (a[i - 1] != b[j - 1])});
    std::swap(prev, cur);
  }
  return prev[b.size()];
}

std::string Nearest(const OptionTable& table, const std::string& key) {
  std::string best;
  int best_d = std::numeric_limits<int>::max();
  for (const auto& b : table.Bindings()) {
    const int d = Levenshtein(Lower(key), Lower(b.key));
    if (d < best_d) best_d = d, best = b.key;
  }
  return best_d <= std::max<int>(3, static_cast<int>(key.size()) / 3) ? best : "";
}

// Strips the quotes of a YAML scalar ("..." or '...'); unquoted text is taken as is.
std::string Unquote(const std::string& v, const std::string& where, const std::string& key) {
  if (!v.empty() && (v.front() == '"' || v.front() == '\'')) {
    if (v.size() < 2 || v.back() != v.front())
      throw InputError(where + ": " + key + ": unterminated quoted value " + Quoted(v) +
                       " (expected the closing " + std::string(1, v.front()) + ")");
    return v.substr(1, v.size() - 2);
  }
  return v;
}

// Removes a '#' comment that is not inside quotes. As in YAML (and OpenCV's FileStorage,
// which read the original's files), '#' starts a comment only at the start of the line or after
// a space or tab: "out/run#1.npy" is a value, "out/run.npy # first run" a value and a comment.
std::string StripComment(const std::string& line) {
  char quote = 0;
  for (size_t i = 0; i < line.size(); ++i) {
    const char ch = line[i];
    if (quote) {
      if (ch == quote) quote = 0;
    } else if (ch == '"' || ch == '\'') {
      quote = ch;
    } else if (ch == '#' && (i == 0 || line[i - 1] == ' ' || line[i - 1] == '\t')) {
      return line.substr(0, i);
    }
  }
  return line;
}

void Assign(const OptionBinding& b, const std::string& raw, const std::string& where) {
  b.assign(Unquote(raw, where, b.key), where);
}

}  // namespace

std::string OptionBinding::RangeText() const {
  if (kind == Kind::kText || kind == Kind::kEnumName) return "text";
  if (kind != Kind::kDouble) {
    // Integers are stored as int: an open range ends at the type's limit, which is stated
    // (a value beyond it is refused with this text).
    const auto bound = [](double v) { return std::to_string(static_cast<long long>(v)); };
    const double top = std::isinf(max) ? std::numeric_limits<int>::max() : max;
    return "integer in [" + bound(min) + ", " + bound(top) + "]";
  }
  if (std::isinf(max))
    return "number >= " + FormatNumber(min) +
           (min_excluded ? " (" + FormatNumber(min) + " excluded)" : "");
  return "number in [" + FormatNumber(min) + ", " + FormatNumber(max) + "]";
}

void OptionTable::AddNumber(const char* key, const char* group, const char* meaning, bool is_new,
                            OptionBinding::Kind kind, double min, double max, bool min_excluded,
                            std::function<void(double)> set, std::function<double()> get,
                            std::function<void()> check) {
  OptionBinding b;
  b.key = key;
  b.group = group;
  b.meaning = meaning;
  b.is_new = is_new;
  b.kind = kind;
  b.min = min;
  b.max = max;
  b.min_excluded = min_excluded;
  b.set_number = set;
  b.check = std::move(check);
  const bool integral = kind != OptionBinding::Kind::kDouble;
  const std::string range = b.RangeText();
  b.assign = [set, integral, min, max, min_excluded, range, k = b.key](const std::string& value,
                                                                       const std::string& where) {
    auto fail = [&] {
      throw InputError(where + ": " + k + ": value " + Quoted(value) + " is not valid; expected " +
                       range);
    };
    errno = 0;
    char* end = nullptr;
    const double v = std::strtod(value.c_str(), &end);
    if (value.empty() || end != value.c_str() + value.size() || errno == ERANGE ||
        !std::isfinite(v))
      fail();
    if (integral && (v != std::floor(v) || std::fabs(v) > std::numeric_limits<int>::max())) fail();
    if (v < min || v > max || (min_excluded && v == min)) fail();
    set(v);
  };
  b.format = [get, integral] {
    const double v = get();
    return integral ? std::to_string(static_cast<long long>(v)) : FormatNumber(v);
  };
  b.owner = owner_;
  bindings_.push_back(std::move(b));
}

void OptionTable::AddText(const char* key, const char* group, const std::string& meaning,
                          bool is_new, std::function<void(const std::string&)> set,
                          std::function<std::string()> get, std::function<void()> check) {
  OptionBinding b;
  b.key = key;
  b.group = group;
  b.meaning = meaning;
  b.is_new = is_new;
  b.kind = OptionBinding::Kind::kText;
  b.assign = [set](const std::string& value, const std::string&) { set(value); };
  b.format = [get] { return "\"" + get() + "\""; };
  b.check = std::move(check);
  b.owner = owner_;
  bindings_.push_back(std::move(b));
}

void OptionTable::AddEnum(const char* key, const char* group, const std::string& meaning,
                          bool is_new, std::function<void(const std::string&)> set,
                          std::function<std::string()> get, std::function<void()> check) {
  AddText(key, group, meaning, is_new, nullptr, std::move(get), std::move(check));
  OptionBinding& b = bindings_.back();
  b.kind = OptionBinding::Kind::kEnumName;
  // The enum's own parser names the key; the place of the value is added in front.
  b.assign = [set](const std::string& value, const std::string& where) {
    try {
      set(value);
    } catch (const InputError& e) {
      throw InputError(where + ": " + e.what());
    }
  };
}

const OptionBinding* OptionTable::Find(const std::string& key) const {
  for (const auto& b : bindings_)
    if (key == b.key) return &b;
  return nullptr;
}

const OptionBinding& OptionTable::Lookup(const std::string& key, const std::string& where) const {
  if (const OptionBinding* b = Find(key)) return *b;
  const std::string near = Nearest(*this, key);
  throw InputError(where + ": unknown key " + Quoted(key) +
                   (near.empty() ? "" : "; did you mean " + Quoted(near) + "?") +
                   " (Test_OpenABLE --help-keys lists every key)");
}

void ParseOptionText(const OptionTable& table, const std::string& contents,
                     const std::string& name) {
  // A binary file (an image, random bytes) given as the configuration: say so in one line
  // rather than quote its first "line" of bytes. Text has no control characters but tab, CR,
  // LF and form feed.
  for (std::size_t i = 0; i < contents.size() && i < 65536; ++i) {
    const auto u = static_cast<unsigned char>(contents[i]);
    if ((u < 0x20 && u != '\t' && u != '\n' && u != '\r' && u != '\f') || u == 0x7f)
      throw InputError("configuration file " + Quoted(name) + " is not text (byte " +
                       std::to_string(i) + " is " + Quoted(std::string(1, contents[i])) +
                       "); expected a Config.txt of lines Key: value");
  }
  std::istringstream in(contents);
  std::map<std::string, int> seen;
  std::string line;
  int number = 0;
  bool any_key = false;
  while (std::getline(in, line)) {
    ++number;
    const std::string where = Escaped(name) + ":" + std::to_string(number);
    std::string text = Trim(StripComment(line));
    if (number == 1 && text.rfind("\xEF\xBB\xBF", 0) == 0) text = Trim(text.substr(3));  // BOM
    if (text.empty() || text.rfind("%YAML", 0) == 0 || text == "---" || text == "...") continue;
    const auto colon = text.find(':');
    if (colon == std::string::npos || colon == 0)
      throw InputError(where + ": line " + Quoted(Trim(line).substr(0, 80)) +
                       " is not of the form Key: value");
    const std::string key = Trim(text.substr(0, colon));
    const std::string value = Trim(text.substr(colon + 1));
    const OptionBinding& b = table.Lookup(key, where);
    if (auto it = seen.find(key); it != seen.end())
      throw InputError(where + ": " + key + ": given twice (first at line " +
                       std::to_string(it->second) + ")");
    seen[key] = number;
    Assign(b, value, where);
    any_key = true;
  }
  if (!any_key)
    throw InputError("configuration file " + Quoted(name) +
                     " holds no key (expected lines of the form Key: value)");
}

void ApplyOptionOverride(const OptionTable& table, const std::string& assignment,
                         const std::string& where) {
  const auto eq = assignment.find('=');
  if (eq == std::string::npos || eq == 0)
    throw InputError(where + ": " + Quoted(assignment) + " is not of the form Key=Value");
  const std::string key = Trim(assignment.substr(0, eq));
  Assign(table.Lookup(key, where), Trim(assignment.substr(eq + 1)), where);
}

namespace {

// Calls group(name) before the first binding of each group, then binding(b), in table order.
void ForEachByGroup(const OptionTable& table, const std::function<void(const std::string&)>& group,
                    const std::function<void(const OptionBinding&)>& binding) {
  std::string current;
  for (const auto& b : table.Bindings()) {
    if (current != b.group) {
      current = b.group;
      group(current);
    }
    binding(b);
  }
}

}  // namespace

std::string FormatOptionText(const OptionTable& table) {
  std::ostringstream os;
  os << "%YAML:1.0\n";
  ForEachByGroup(
      table, [&](const std::string& g) { os << "\n# --- " << g << " ---\n"; },
      [&](const OptionBinding& b) {
        os << "# " << b.meaning << "\n" << b.key << ": " << b.format() << "\n";
      });
  return os.str();
}

std::vector<std::string> OptionGroups(const OptionTable& table) {
  std::vector<std::string> groups;
  ForEachByGroup(
      table, [&](const std::string& g) { groups.push_back(g); }, [](const OptionBinding&) {});
  return groups;
}

std::string OptionHelpText(const OptionTable& table, const std::string& group) {
  std::ostringstream os;
  bool shown = group.empty();
  ForEachByGroup(
      table,
      [&](const std::string& g) {
        shown = group.empty() || g == group;
        if (shown) os << "\n" << g << ":\n";
      },
      [&](const OptionBinding& b) {
        if (!shown) return;
        os << "  " << b.key << (b.is_new ? " (new)" : "") << "  [" << b.RangeText() << ", default "
           << b.format() << "]\n";
        // Wrap the meaning at about 90 columns, indented.
        std::istringstream words(b.meaning);
        std::string word, line = "      ";
        while (words >> word) {
          if (line.size() + word.size() + 1 > 92) {
            os << line << "\n";
            line = "      ";
          }
          line += (line.size() > 6 ? " " : "") + word;
        }
        os << line << "\n";
      });
  return os.str();
}

std::string OptionMarkdown(const OptionTable& table) {
  std::ostringstream os;
  ForEachByGroup(
      table,
      [&](const std::string& g) {
        os << "\n### " << g << "\n\n| key | values | default | meaning |\n|---|---|---|---|\n";
      },
      [&](const OptionBinding& b) {
        std::string meaning = b.meaning;
        std::string::size_type pos = 0;
        while ((pos = meaning.find('|', pos)) != std::string::npos) {
          meaning.replace(pos, 1, "\\|");
          pos += 2;
        }
        os << "| `" << b.key << "`" << (b.is_new ? " (new)" : "") << " | " << b.RangeText()
           << " | `" << b.format() << "` | " << meaning << " |\n";
      });
  return os.str();
}

}  // namespace openable
