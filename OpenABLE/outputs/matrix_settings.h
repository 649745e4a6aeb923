// The settings a saved matrix remembers: beside every matrix file a run writes (Npy_name,
// Txt_name) a small JSON file, the matrix's path with ".json" added (m.npy.json), holds the
// settings that shaped the matrix and those its evaluation used, the traversal sizes and the
// score (docs/output_formats.md, "The settings beside a matrix"). openable_evaluate and
// Python read it, so that a saved matrix evaluated later gives the run's own figures unless the
// user overrides a setting, and says so.
#pragma once

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "OpenABLE/run/result.h"
#include "config/config.h"

namespace openable {

// The keys whose values the evaluation of a matrix reads (EvaluationSettingsFrom): ground truth,
// tolerance, exclusion, vicinity, the frame range, the match score and its acceptance, and the
// sequence settings the consistency acceptance follows. A reader applies these.
const std::vector<std::string>& MatrixEvaluationKeys();

// The value of `key` in `config` as a settings file holds it and --set takes it: Config.txt's
// text without the quotes of a text value.
std::string MatrixSettingValue(const Config& config, const std::string& key);

// The path of the settings file of `matrix_path`: matrix_path + ".json".
std::string MatrixSettingsPath(const std::string& matrix_path);

// The settings file of a matrix `config` and `result` wrote at `matrix_path`; `thresholded`:
// the file holds M'' of Eq. 9 (Txt_name with Threshold set), not distances. Paths of the
// ground truth are made absolute, so that the file can be evaluated from another folder.
std::string EncodeMatrixSettings(const Config& config, const RunResult& result,
                                 const std::string& matrix_path, bool thresholded);

// What a reader takes from a settings file.
struct SavedMatrixSettings {
  std::string path;  // the settings file
  std::vector<std::pair<std::string, std::string>> keys;  // MatrixEvaluationKeys, "Key", value
  int reference_frames = 0;  // two traversals in one square matrix: the first traversal's frames
  bool thresholded = false;  // M'' of Eq. 9: not distances
  std::string score;         // Match_score
};

// The settings file of `matrix_path` when there is one (std::nullopt otherwise). Throws
// InputError naming the file when it cannot be read or is not such a file.
std::optional<SavedMatrixSettings> ReadMatrixSettings(const std::string& matrix_path);

}  // namespace openable
