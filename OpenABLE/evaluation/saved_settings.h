// Reading the settings a saved matrix remembers (the JSON file beside it, m.npy.json, that
// OpenABLE/outputs/matrix_settings.h writes; docs/output_formats.md): what openable_evaluate
// and Python take from it, checked to hold together and to fit the matrix.
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace openable {

// The keys whose values the evaluation of a matrix reads (EvaluationSettingsFrom): ground truth,
// tolerance, exclusion, vicinity, the frame range, the match score and its acceptance, and the
// sequence settings the consistency acceptance follows. A reader applies these.
const std::vector<std::string>& MatrixEvaluationKeys();

// The path of the settings file of `matrix_path`: matrix_path + ".json".
std::string MatrixSettingsPath(const std::string& matrix_path);

// What a reader takes from a settings file.
struct SavedMatrixSettings {
  std::string path;                                       // the settings file
  std::vector<std::pair<std::string, std::string>> keys;  // MatrixEvaluationKeys, "Key", value
  int reference_frames = 0;  // two traversals in one square matrix: the first traversal's frames
  bool thresholded = false;  // M'' of Eq. 9: not distances
  std::string score;         // Match_score
  int rows = 0, cols = 0;    // the size of the matrix the file was written with
  std::vector<int> traversal_frames;  // each traversal's frames, in matrix order
};

// The settings file of `matrix_path` when there is one (std::nullopt otherwise). Throws
// InputError naming the file when it cannot be read, is not such a file, or does not hold
// together: a run's matrix is square, of as many rows as its traversals have frames in all;
// `reference_frames` is the first traversal's frames when there are two (else 0, here and in
// `python_evaluate`); no traversal has more frames than Final_image - Initial_image.
std::optional<SavedMatrixSettings> ReadMatrixSettings(const std::string& matrix_path);
// The same checks on the text of a settings file at `path`.
SavedMatrixSettings DecodeMatrixSettings(std::string_view text, const std::string& path);

// Refuses, in one line naming both sizes, a matrix of `rows` x `cols` read from `matrix_path`
// that is not the size its settings file `saved` was written with (a file beside another
// run's matrix, or a matrix replaced).
void CheckMatrixFitsSettings(const SavedMatrixSettings& saved, const std::string& matrix_path,
                             int rows, int cols);

}  // namespace openable
