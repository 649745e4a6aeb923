#include "OpenABLE/evaluation/saved_settings.h"

#include <charconv>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <system_error>

#include "OpenABLE/base/error.h"
#include "OpenABLE/base/input_file.h"
#include "OpenABLE/base/strings.h"
#include "OpenABLE/io/json.h"

namespace openable {

namespace fs = std::filesystem;

const std::vector<std::string>& MatrixEvaluationKeys() {
  static const std::vector<std::string> keys = {"Ground_truth_type",
                                                "Ground_truth",
                                                "Ground_truth_2",
                                                "Ground_truth_base",
                                                "Ground_truth_radius",
                                                "Ground_truth_heading",
                                                "Ground_truth_min_gap",
                                                "Ground_truth_time_tolerance",
                                                "Ground_truth_axes",
                                                "Tolerance",
                                                "Exclusion",
                                                "Vicinity",
                                                "Initial_image",
                                                "Final_image",
                                                "Match_score",
                                                "Match_score_window",
                                                "Match_threshold",
                                                "Match_consistency",
                                                "Image_sequences",
                                                "Sequence_partial",
                                                "Sequence_direction",
                                                "Ground_truth_soft"};
  return keys;
}

std::string MatrixSettingsPath(const std::string& matrix_path) { return matrix_path + ".json"; }

SavedMatrixSettings DecodeMatrixSettings(std::string_view text, const std::string& path) {
  const auto refuse = [&](const std::string& why) {
    return InputError("settings of the matrix " + Quoted(path) + ": " + why +
                      "; expected the JSON file OpenABLE writes beside a matrix (delete or "
                      "rename it to evaluate the matrix without it)");
  };
  Json o;
  try {
    o = Json::parse(text);
  } catch (const std::exception&) {
    throw refuse("not valid JSON");
  }
  if (!o.is_object() || !o.contains("evaluation_keys") || !o["evaluation_keys"].is_object())
    throw refuse("no \"evaluation_keys\" object");
  const auto count = [&](const Json& v, const std::string& name, int least) {
    if (!v.is_number_integer() || v.get<std::int64_t>() < least ||
        v.get<std::int64_t>() > std::numeric_limits<int>::max())
      throw refuse(name + " is not a number of frames >= " + std::to_string(least));
    return static_cast<int>(v.get<std::int64_t>());
  };
  const auto text_member = [&](const char* name, const char* absent) {
    if (!o.contains(name)) return std::string(absent);
    if (!o[name].is_string()) throw refuse("\"" + std::string(name) + "\" is not a string");
    return o[name].get<std::string>();
  };
  SavedMatrixSettings s;
  s.path = path;
  for (const std::string& key : MatrixEvaluationKeys()) {
    if (!o["evaluation_keys"].contains(key)) continue;
    const Json& v = o["evaluation_keys"][key];
    if (!v.is_string()) throw refuse(Quoted(key) + " is not a string");
    s.keys.emplace_back(key, v.get<std::string>());
  }
  if (o.contains("reference_frames"))
    s.reference_frames = count(o["reference_frames"], "\"reference_frames\"", 0);
  s.thresholded = text_member("content", "distances") == "thresholded";
  s.score = text_member("match_score", "");
  // The sizes, which must hold together: a file edited within its own sizes, or one whose
  // numbers disagree, would evaluate another block of the matrix without a word.
  if (!o.contains("rows") || !o.contains("cols"))
    throw refuse("no \"rows\" and \"cols\" (the matrix's size)");
  s.rows = count(o["rows"], "\"rows\"", 1);
  s.cols = count(o["cols"], "\"cols\"", 1);
  if (!o.contains("traversals") || !o["traversals"].is_array() || o["traversals"].empty() ||
      o["traversals"].size() > 2)
    throw refuse("\"traversals\" is not a list of one or two traversals");
  std::int64_t frames = 0;
  for (const Json& t : o["traversals"]) {
    if (!t.is_object() || !t.contains("frames")) throw refuse("a traversal without \"frames\"");
    s.traversal_frames.push_back(count(t["frames"], "a traversal's \"frames\"", 1));
    frames += s.traversal_frames.back();
  }
  const std::string sizes = std::to_string(s.rows) + "x" + std::to_string(s.cols);
  if (s.rows != s.cols || frames != s.rows)
    throw refuse("a " + sizes + " matrix of " + std::to_string(frames) +
                 " frames in all; expected a square matrix of as many rows as frames");
  const int expected_reference = s.traversal_frames.size() == 2 ? s.traversal_frames.front() : 0;
  if (s.reference_frames != expected_reference)
    throw refuse("\"reference_frames\" " + std::to_string(s.reference_frames) + " with " +
                 std::to_string(s.traversal_frames.size()) + " traversal" +
                 (s.traversal_frames.size() == 2 ? "s" : "") + "; expected " +
                 std::to_string(expected_reference) +
                 (expected_reference ? " (the first traversal's frames)" : ""));
  if (o.contains("python_evaluate") && o["python_evaluate"].is_object()) {
    const Json& py = o["python_evaluate"];
    const int py_reference =
        py.contains("reference_frames")
            ? count(py["reference_frames"], "\"python_evaluate\" \"reference_frames\"", 0)
            : 0;
    if (py_reference != s.reference_frames)
      throw refuse("\"python_evaluate\" has reference_frames " + std::to_string(py_reference) +
                   ", the file " + std::to_string(s.reference_frames) + "; expected one value");
  }
  // The frame range the evaluation cuts the ground truth at, against the frames read in it.
  int initial = 0, final = -1;
  for (const auto& [key, value] : s.keys) {
    if (key != "Initial_image" && key != "Final_image") continue;
    int parsed = 0;
    const auto [end, ec] = std::from_chars(value.data(), value.data() + value.size(), parsed);
    if (ec != std::errc() || end != value.data() + value.size())
      throw refuse(key + " " + Quoted(value) + " is not a whole number");
    (key == "Initial_image" ? initial : final) = parsed;
  }
  if (final != -1)
    for (const int f : s.traversal_frames)
      if (static_cast<std::int64_t>(f) > static_cast<std::int64_t>(final) - initial)
        throw refuse("a traversal of " + std::to_string(f) + " frames within Initial_image " +
                     std::to_string(initial) + " and Final_image " + std::to_string(final) +
                     "; expected at most " +
                     std::to_string(static_cast<std::int64_t>(final) - initial));
  return s;
}

void CheckMatrixFitsSettings(const SavedMatrixSettings& saved, const std::string& matrix_path,
                             int rows, int cols) {
  if (rows == saved.rows && cols == saved.cols) return;
  std::string traversals;
  for (std::size_t i = 0; i < saved.traversal_frames.size(); ++i)
    traversals += (i ? " and " : "") + std::to_string(saved.traversal_frames[i]);
  throw InputError("matrix " + Quoted(matrix_path) + ": " + std::to_string(rows) + "x" +
                   std::to_string(cols) + ", but its settings file " + Quoted(saved.path) +
                   " was written with a " + std::to_string(saved.rows) + "x" +
                   std::to_string(saved.cols) + " matrix (traversals of " + traversals +
                   " frames); expected the settings file of this matrix (delete or rename it " +
                   "to evaluate the matrix without it)");
}

std::optional<SavedMatrixSettings> ReadMatrixSettings(const std::string& matrix_path) {
  const std::string path = MatrixSettingsPath(matrix_path);
  std::error_code ec;
  if (!fs::exists(path, ec)) return std::nullopt;
  return DecodeMatrixSettings(
      ReadInputFile(path, "settings of the matrix " + Quoted(path),
                    "expected the JSON file OpenABLE writes beside a matrix"),
      path);
}

}  // namespace openable
