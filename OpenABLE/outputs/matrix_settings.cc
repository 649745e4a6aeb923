#include "OpenABLE/outputs/matrix_settings.h"

#include <filesystem>

#include "OpenABLE/base/error.h"
#include "OpenABLE/base/input_file.h"
#include "OpenABLE/base/strings.h"
#include "OpenABLE/base/version.h"
#include "OpenABLE/io/json.h"
#include "OpenABLE/run/evaluate.h"

namespace openable {

namespace fs = std::filesystem;

const std::vector<std::string>& MatrixEvaluationKeys() {
  static const std::vector<std::string> keys = {
      "Ground_truth_type", "Ground_truth",       "Ground_truth_2",     "Ground_truth_base",
      "Ground_truth_radius", "Ground_truth_heading", "Ground_truth_min_gap",
      "Ground_truth_time_tolerance", "Ground_truth_axes", "Tolerance", "Exclusion", "Vicinity",
      "Initial_image", "Final_image", "Match_score", "Match_score_window", "Match_threshold",
      "Match_consistency", "Image_sequences", "Sequence_partial", "Sequence_direction",
      "Ground_truth_soft"};
  return keys;
}

std::string MatrixSettingsPath(const std::string& matrix_path) { return matrix_path + ".json"; }

std::string MatrixSettingValue(const Config& config, const std::string& key) {
  std::string v = ConfigValueText(config, key);
  if (v.size() >= 2 && v.front() == '"' && v.back() == '"') v = v.substr(1, v.size() - 2);
  return v;
}

namespace {

std::string Absolute(const std::string& path) {
  if (path.empty()) return path;
  std::error_code ec;
  const fs::path a = fs::absolute(path, ec);
  return ec ? path : a.lexically_normal().string();
}

}  // namespace

std::string EncodeMatrixSettings(const Config& config, const RunResult& result,
                                 const std::string& matrix_path, bool thresholded) {
  Config c = config;
  c.evaluation.truth.path = Absolute(c.evaluation.truth.path);
  c.evaluation.truth.path_2 = Absolute(c.evaluation.truth.path_2);
  Json o;
  o["openable_version"] = kVersion;
  o["matrix"] = fs::path(matrix_path).filename().string();
  o["content"] = thresholded ? "thresholded" : "distances";
  o["rows"] = result.normalized.rows;
  o["cols"] = result.normalized.cols;
  Json& traversals = o["traversals"] = Json::array();
  for (const Traversal& t : result.traversals)
    traversals.push_back({{"key", t.key}, {"path", t.path}, {"frames", t.frames}});
  o["reference_frames"] = result.traversals.size() == 2 ? result.traversals[0].frames : 0;
  o["match_score"] = MatrixSettingValue(c, "Match_score");
  Json& keys = o["evaluation_keys"] = Json::object();
  for (const std::string& key : MatrixEvaluationKeys()) keys[key] = MatrixSettingValue(c, key);
  // The same settings as the keywords of Python's openable.evaluate (docs/python.md).
  const EvaluationSettings s = EvaluationSettingsFrom(c);
  Json& py = o["python_evaluate"] = Json::object();
  if (!s.truth.type.IsNone()) {
    py["truth_type"] = GroundTruthTypeName(s.truth.type);
    py["truth_file"] = s.truth.path;
    if (!s.truth.path_2.empty()) py["truth_file_2"] = s.truth.path_2;
    if (!s.truth.soft_path.empty()) py["truth_file_soft"] = s.truth.soft_path;
  }
  py["base"] = s.truth.base;
  py["first_frame"] = s.truth.first_frame;
  py["range_selected"] = s.truth.range_selected;
  if (result.traversals.size() == 2) py["reference_frames"] = result.traversals[0].frames;
  py["tolerance"] = s.options.tolerance;
  py["exclusion"] = s.options.exclusion;
  py["vicinity"] = s.options.vicinity;
  py["radius"] = json::Number(s.truth.radius);
  py["heading_limit"] = json::Number(s.truth.heading_limit);
  py["min_frame_gap"] = s.truth.min_frame_gap;
  py["axes"] = s.truth.axes;
  py["score"] = EnumName(s.options.score);
  py["score_window"] = s.options.score_window;
  if (s.options.accept_threshold >= 0)
    py["accept_threshold"] = json::Number(s.options.accept_threshold);
  py["accept_consistency"] = s.options.accept_consistency;
  py["sequence_length"] = s.options.agreement.sequence_length;
  py["partial"] = EnumName(s.options.agreement.partial);
  py["direction"] = EnumName(s.options.agreement.direction);
  // Every key of the run, for the record: what else shaped the matrix (descriptor, sequences,
  // preprocessing...). Readers apply only evaluation_keys.
  Json& all = o["settings"] = Json::object();
  for (const std::string& key : ConfigKeyNames()) all[key] = MatrixSettingValue(c, key);
  return json::Dump(o);
}

std::optional<SavedMatrixSettings> ReadMatrixSettings(const std::string& matrix_path) {
  const std::string path = MatrixSettingsPath(matrix_path);
  std::error_code ec;
  if (!fs::exists(path, ec)) return std::nullopt;
  const std::string text = ReadInputFile(path, "settings of the matrix " + Quoted(path),
                                         "expected the JSON file OpenABLE writes beside a matrix");
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
  SavedMatrixSettings s;
  s.path = path;
  for (const std::string& key : MatrixEvaluationKeys()) {
    if (!o["evaluation_keys"].contains(key)) continue;
    const Json& v = o["evaluation_keys"][key];
    if (!v.is_string()) throw refuse(Quoted(key) + " is not a string");
    s.keys.emplace_back(key, v.get<std::string>());
  }
  if (o.contains("reference_frames")) {
    if (!o["reference_frames"].is_number_integer() || o["reference_frames"].get<int>() < 0)
      throw refuse("\"reference_frames\" is not a number of frames");
    s.reference_frames = o["reference_frames"].get<int>();
  }
  s.thresholded = o.value("content", std::string("distances")) == "thresholded";
  s.score = o.value("match_score", std::string());
  return s;
}

}  // namespace openable
