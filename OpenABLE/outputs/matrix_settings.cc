#include "OpenABLE/outputs/matrix_settings.h"

#include <filesystem>

#include "OpenABLE/base/error.h"
#include "OpenABLE/base/strings.h"
#include "OpenABLE/base/version.h"
#include "OpenABLE/io/json.h"
#include "OpenABLE/run/evaluate.h"

namespace openable {

namespace fs = std::filesystem;

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
  py["score"] = EnumName(s.options.score.kind);
  py["score_window"] = s.options.score.window;
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

}  // namespace openable
