// The settings a saved matrix remembers: beside every matrix file a run writes (Npy_name,
// Txt_name) a small JSON file, the matrix's path with ".json" added (m.npy.json), holds the
// settings that shaped the matrix and those its evaluation used, the traversal sizes and the
// score (docs/output_formats.md, "The settings beside a matrix"). openable_evaluate and
// Python read it, so that a saved matrix evaluated later gives the run's own figures unless the
// user overrides a setting, and says so. This file writes it; the reader is
// OpenABLE/evaluation/saved_settings.h.
#pragma once

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "OpenABLE/evaluation/saved_settings.h"
#include "OpenABLE/run/result.h"
#include "config/config.h"

namespace openable {

// The value of `key` in `config` as a settings file holds it and --set takes it: Config.txt's
// text without the quotes of a text value.
std::string MatrixSettingValue(const Config& config, const std::string& key);

// The settings file of a matrix `config` and `result` wrote at `matrix_path`; `thresholded`:
// the file holds M'' of Eq. 9 (Txt_name with Threshold set), not distances. Paths of the
// ground truth are made absolute, so that the file can be evaluated from another folder.
std::string EncodeMatrixSettings(const Config& config, const RunResult& result,
                                 const std::string& matrix_path, bool thresholded);

}  // namespace openable
