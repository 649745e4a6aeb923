// Keys bound onto fields of option structs (after COLMAP's OptionManager: one binding per key
// drives reading, --set overrides, --help, the Markdown reference and formatting).
//
// A table is built over one instance of the options it binds (config/config.h builds the one
// table of Config.txt over a Config); each binding knows its key, its group in --help, its
// range or choices, its meaning, and the struct that owns the field, whose Check() validates
// it. The table checks the type and range of a value as it is read, so that an error names the
// file and line; everything else about a value is the owner's Check().
#pragma once

#include <functional>
#include <limits>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>
#include <vector>

#include "OpenABLE/base/enum_names.h"

namespace openable {

inline constexpr double kNoLimit = std::numeric_limits<double>::infinity();

// One key bound to one field.
struct OptionBinding {
  enum class Kind { kInt, kDouble, kText, kBool, kEnumNumber, kEnumName };
  std::string key;
  std::string group;
  std::string meaning;
  bool is_new = true;  // not a key of the original OpenABLE
  Kind kind = Kind::kText;
  double min = 0, max = 0;    // numbers, inclusive (kInt, kDouble, kBool, kEnumNumber)
  bool min_excluded = false;  // kDouble: min itself is not valid (a number > min)
  // Reads `value` (unquoted) into the field; throws InputError "<where>: <key>: value "..."
  // is not valid; expected <RangeText()>" on a value of the wrong type or out of range.
  std::function<void(const std::string& value, const std::string& where)> assign;
  // The value as Config.txt holds it (text quoted).
  std::function<std::string()> format;
  // Numeric kinds: sets the field to `value` without any check (tests walk the ranges).
  std::function<void(double value)> set_number;
  // Check() of the struct that owns the field, and that struct (to tell which keys belong to
  // one module: the settings that change a descriptor row, say).
  std::function<void()> check;
  const void* owner = nullptr;

  // "integer in [0, 2]", "number >= 0", "number >= 0 (0 excluded)", or "text".
  std::string RangeText() const;
};

class OptionTable {
 public:
  // Binds `field`, a member of `owner` (any struct with a const Check()), to `key`.
  template <typename Owner>
  void Add(const char* key, const char* group, Owner& owner, int& field, double min, double max,
           const char* meaning, bool is_new = true) {
    AddNumber(
        key, group, meaning, is_new, OptionBinding::Kind::kInt, min, max, false,
        [&field](double v) { field = static_cast<int>(v); },
        [&field] { return static_cast<double>(field); }, CheckOf(owner));
  }
  template <typename Owner>
  void Add(const char* key, const char* group, Owner& owner, double& field, double min, double max,
           const char* meaning, bool is_new = true, bool min_excluded = false) {
    AddNumber(
        key, group, meaning, is_new, OptionBinding::Kind::kDouble, min, max, min_excluded,
        [&field](double v) { field = v; }, [&field] { return field; }, CheckOf(owner));
  }
  // A flag read as 0 or 1, as the original's keys are.
  template <typename Owner>
  void Add(const char* key, const char* group, Owner& owner, bool& field, const char* meaning,
           bool is_new = true) {
    AddNumber(
        key, group, meaning, is_new, OptionBinding::Kind::kBool, 0, 1, false,
        [&field](double v) { field = v != 0; }, [&field] { return field ? 1.0 : 0.0; },
        CheckOf(owner));
  }
  template <typename Owner>
  void Add(const char* key, const char* group, Owner& owner, std::string& field,
           const char* meaning, bool is_new = true) {
    AddText(
        key, group, meaning, is_new, [&field](const std::string& v) { field = v; },
        [&field] { return field; }, CheckOf(owner));
  }
  // An enum read as the number of its value (0, 1, ...), as the original's keys are.
  template <typename Owner, typename E>
  void AddEnumNumber(const char* key, const char* group, Owner& owner, E& field,
                     const char* meaning, bool is_new = true) {
    static_assert(std::is_enum_v<E>);
    const double last = static_cast<double>(EnumNames<E>().size()) - 1;
    AddNumber(
        key, group, meaning, is_new, OptionBinding::Kind::kEnumNumber, 0, last, false,
        [&field](double v) { field = static_cast<E>(static_cast<int>(v)); },
        [&field] { return static_cast<double>(field); }, CheckOf(owner));
  }
  // An enum read by the name of its value (EnumNames, any case).
  template <typename Owner, typename E>
  void AddEnumName(const char* key, const char* group, Owner& owner, E& field, const char* meaning,
                   bool is_new = true) {
    static_assert(std::is_enum_v<E>);
    AddEnum(
        key, group, meaning, is_new,
        [&field, k = std::string(key)](const std::string& v) { field = ParseEnum<E>(v, k); },
        [&field] { return EnumName(field); }, CheckOf(owner));
  }
  // An enum with its own reader and writer (a name for "none" that reads as empty text, say).
  template <typename Owner, typename E>
  void AddEnumName(const char* key, const char* group, Owner& owner, E& field,
                   E (*parse)(const std::string&), std::string (*format)(E), const char* meaning,
                   bool is_new = true) {
    AddEnum(
        key, group, meaning, is_new, [&field, parse](const std::string& v) { field = parse(v); },
        [&field, format] { return format(field); }, CheckOf(owner));
  }

  // A name of a registry (an approximate-search engine, say) in a text field: `parse` returns
  // the value as the field holds it, or throws InputError naming `key` and the valid names;
  // `meaning` is made at run time from the same registry.
  template <typename Owner>
  void AddName(const char* key, const char* group, Owner& owner, std::string& field,
               std::string (*parse)(std::string_view text, const std::string& key),
               const std::string& meaning, bool is_new = true) {
    AddEnum(
        key, group, meaning, is_new,
        [&field, parse, k = std::string(key)](const std::string& v) { field = parse(v, k); },
        [&field] { return field; }, CheckOf(owner));
  }

  const std::vector<OptionBinding>& Bindings() const& { return bindings_; }
  // On a temporary table (`for (auto& b : ConfigTable(c).Bindings())`), a copy that lives as
  // long as the loop; the bindings still refer to the fields of the options given.
  std::vector<OptionBinding> Bindings() && { return std::move(bindings_); }
  // The binding of `key` (exact name), or nullptr.
  const OptionBinding* Find(const std::string& key) const;
  // The binding of `key`; throws InputError "<where>: unknown key "K"; did you mean "L"?".
  const OptionBinding& Lookup(const std::string& key, const std::string& where) const;

 private:
  // The owner's Check(); notes the owner for the binding being added (every Add passes it as
  // an argument of the private adder, which stores it).
  template <typename Owner>
  std::function<void()> CheckOf(Owner& owner) {
    owner_ = &owner;
    return [&owner] { owner.Check(); };
  }
  void AddNumber(const char* key, const char* group, const char* meaning, bool is_new,
                 OptionBinding::Kind kind, double min, double max, bool min_excluded,
                 std::function<void(double)> set, std::function<double()> get,
                 std::function<void()> check);
  void AddText(const char* key, const char* group, const std::string& meaning, bool is_new,
               std::function<void(const std::string&)> set, std::function<std::string()> get,
               std::function<void()> check);
  void AddEnum(const char* key, const char* group, const std::string& meaning, bool is_new,
               std::function<void(const std::string&)> set, std::function<std::string()> get,
               std::function<void()> check);

  std::vector<OptionBinding> bindings_;
  const void* owner_ = nullptr;
};

// Reads the flat "Key: value" subset of YAML that the original's OpenCV FileStorage files use
// ("%YAML:1.0" first line optional, '#' comments, strings quoted or not) into the fields of
// `table`; `name` stands for the file in messages. Keys not present keep their values. Throws
// InputError with one line "<name>:<line>: <Key>: <problem>" on a file that is not text, a
// line that is not "Key: value", an unknown key (naming the nearest valid one), a duplicated
// key, or a value of the wrong type or out of range.
void ParseOptionText(const OptionTable& table, const std::string& text, const std::string& name);

// Applies one "Key=Value" (from --set). Same checks and messages, with `where` ("--set",
// "--vary") as the place.
void ApplyOptionOverride(const OptionTable& table, const std::string& assignment,
                         const std::string& where = "--set");

// The whole table in the format ParseOptionText reads, a comment with each key's meaning.
std::string FormatOptionText(const OptionTable& table);

// Every key for --help-keys: grouped, each with its range, its value in `table` (the defaults
// when the table is over default options) and its meaning wrapped at about 90 columns. Only the
// keys of `group` (one of OptionGroups, exactly) when it is not empty.
std::string OptionHelpText(const OptionTable& table, const std::string& group = "");

// The groups of the table's keys, in their order.
std::vector<std::string> OptionGroups(const OptionTable& table);

// The same as Markdown tables, one per group (docs/configuration.md).
std::string OptionMarkdown(const OptionTable& table);

}  // namespace openable
